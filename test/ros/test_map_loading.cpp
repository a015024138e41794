// Map location resolution and loading for the localizer node (no roscore).
#include "fdml_localization/ros/map_loading.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <string>

namespace fdml_localization
{
namespace
{
const std::string kTestMap = std::string(FDML_SOURCE_DIR) + "/test/data/node_test_room.poly";

/// The message of the MapLoadError thrown by @p fn ("" when nothing is thrown).
template <typename Fn>
std::string errorOf(Fn fn)
{
  try
  {
    fn();
  }
  catch (const MapLoadError& error)
  {
    return error.what();
  }
  return "";
}

TEST(MapLoading, PlainAndFilePathsResolveToThemselves)
{
  EXPECT_EQ(resolveMapPath("/abs/room.poly"), "/abs/room.poly");
  EXPECT_EQ(resolveMapPath("relative/room.poly"), "relative/room.poly");
  EXPECT_EQ(resolveMapPath("file:///abs/room.poly"), "/abs/room.poly");
}

TEST(MapLoading, PackageUrisResolveThroughThePackagePath)
{
  // Needs the workspace on ROS_PACKAGE_PATH (as catkin's run_tests sets it up).
  const std::string path = resolveMapPath("package://fdml_localization/test/data/node_test_room.poly");
  EXPECT_EQ(loadMap(path)->map().edges().size(), loadMap(kTestMap)->map().edges().size()) << path;
}

TEST(MapLoading, MalformedOrUnknownPackageUrisAreNamed)
{
  EXPECT_NE(errorOf([] { resolveMapPath("package://"); }).find("package://PACKAGE/"), std::string::npos);
  EXPECT_NE(errorOf([] { resolveMapPath("package://fdml_localization"); }).find("~map_file"), std::string::npos);
  const std::string unknown = errorOf([] { resolveMapPath("package://no_such_fdml_package_xyz/maps/a.poly"); });
  EXPECT_NE(unknown.find("no_such_fdml_package_xyz"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("~map_file"), std::string::npos) << unknown;
}

TEST(MapLoading, SearchRegionsLoadLikeMapsAndNameTheirParameter)
{
  EXPECT_EQ(loadSearchRegionFile("", {}), nullptr);
  const auto region = loadSearchRegionFile(kTestMap, {});
  ASSERT_TRUE(region);
  EXPECT_EQ(region->map().bounds().max, loadMap(kTestMap)->map().bounds().max);
  // A grid region: the free region holding the seed point.
  const std::string grid = std::string(FDML_SOURCE_DIR) + "/maps/apartment_grid.yaml";
  const auto largest = loadSearchRegionFile(grid, {});
  ASSERT_TRUE(largest);
  EXPECT_GT(largest->map().area(), 10.0);
  const std::string missing = errorOf([] { loadSearchRegionFile("/nonexistent/fdml/region.poly", {}); });
  EXPECT_NE(missing.find("~search_region"), std::string::npos) << missing;
  EXPECT_NE(missing.find("/nonexistent/fdml/region.poly"), std::string::npos) << missing;
  const std::string wall = errorOf([&grid] { loadSearchRegionFile(grid, { -1000.0, -1000.0 }); });
  EXPECT_NE(wall.find("~search_region"), std::string::npos) << wall;
}

TEST(MapLoading, LoadsAPolyFile)
{
  const auto map = loadMap(kTestMap);
  ASSERT_TRUE(map);
  EXPECT_EQ(map->map().holeCount(), 1u);
  EXPECT_EQ(map->map().outer().size(), 6u);
  // A ray from inside hits the wall at the expected distance (the room spans x in [0, 6] at y = 1).
  EXPECT_NEAR(map->range(core::Pose2(1.0, 1.0, 0.0)), 5.0, 1e-9);
}

TEST(MapLoading, ProblemsNameTheFile)
{
  const std::string missing = errorOf([] { loadMap("/nonexistent/fdml/room.poly"); });
  EXPECT_NE(missing.find("/nonexistent/fdml/room.poly"), std::string::npos) << missing;
  const std::string format = errorOf([] { loadMap(std::string(FDML_SOURCE_DIR) + "/package.xml"); });
  EXPECT_NE(format.find("unknown map file type"), std::string::npos) << format;
  EXPECT_NE(format.find("package.xml"), std::string::npos) << format;

  const std::string path = "/tmp/fdml_map_loading_test_" + std::to_string(::getpid()) + ".poly";
  FILE* file = std::fopen(path.c_str(), "w");
  ASSERT_NE(file, nullptr);
  std::fputs("0 0\n1 0\n", file);  // one ring of two vertices
  std::fclose(file);
  const std::string invalid = errorOf([&path] { loadMap(path); });
  std::remove(path.c_str());
  EXPECT_NE(invalid.find(path), std::string::npos) << invalid;
}

// ---------------------------------------------------------------------------------------------
// map_server YAML maps (issue 9).
// ---------------------------------------------------------------------------------------------

const std::string kTestGrid = std::string(FDML_SOURCE_DIR) + "/test/data/node_test_room_grid.yaml";

TEST(MapLoading, LoadsAMapServerYamlAsAPolygon)
{
  const LoadedMap loaded = loadMapFromFile(kTestGrid);
  ASSERT_TRUE(loaded.map);
  EXPECT_EQ(loaded.source, kTestGrid);
  EXPECT_NEAR(loaded.grid_resolution, 0.05, 1e-12);
  EXPECT_NE(loaded.summary.find("at 0.05 m"), std::string::npos) << loaded.summary;
  EXPECT_NE(loaded.summary.find("holes: "), std::string::npos) << loaded.summary;
  // The test room's pillar survives and its walls are within a cell of the polygon's.
  EXPECT_EQ(loaded.map->map().holeCount(), 1u);
  const auto polygon = loadMap(kTestMap);
  for (const core::Pose2& pose : { core::Pose2(1.0, 1.0, 0.0), core::Pose2(3.0, 2.0, 1.2), core::Pose2(0.7, 3.5, -2.5),
                                   core::Pose2(5.0, 0.5, 2.9), core::Pose2(2.5, 1.75, core::kPi) })
  {
    EXPECT_NEAR(loaded.map->range(pose), polygon->range(pose), 0.1) << pose.x << ", " << pose.y << ", " << pose.theta;
  }
  // A .poly file is no grid.
  EXPECT_EQ(loadMapFromFile(kTestMap).grid_resolution, 0.0);
  EXPECT_TRUE(loadMapFromFile(kTestMap).summary.empty());
}

TEST(MapLoading, ConversionOptionsReachTheCore)
{
  core::GridConversionOptions options;
  options.min_area = 1.0;  // the 0.25 m^2 pillar becomes a speck
  EXPECT_EQ(loadMapFromFile(kTestGrid, options).map->map().holeCount(), 0u);
  options = core::GridConversionOptions();
  options.use_seed = true;
  options.seed_point = core::Vec2(1.75, 1.75);  // inside the pillar
  const std::string error = errorOf([&options] { loadMapFromFile(kTestGrid, options); });
  EXPECT_NE(error.find("seed point"), std::string::npos) << error;
  EXPECT_NE(error.find(kTestGrid), std::string::npos) << error;
  EXPECT_NE(error.find("~map_file"), std::string::npos) << error;
}

TEST(MapLoading, AYamlWithAMissingImageNamesTheImage)
{
  const std::string path = "/tmp/fdml_map_loading_test_" + std::to_string(::getpid()) + ".yaml";
  FILE* file = std::fopen(path.c_str(), "w");
  ASSERT_NE(file, nullptr);
  std::fputs("image: no_such_image_fdml.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
             "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n",
             file);
  std::fclose(file);
  const std::string error = errorOf([&path] { loadMapFromFile(path); });
  std::remove(path.c_str());
  EXPECT_NE(error.find("/tmp/no_such_image_fdml.pgm"), std::string::npos) << error;
  EXPECT_NE(error.find(path), std::string::npos) << error;
}

TEST(MapLoading, AnAllOccupiedGridIsRejectedNamingTheSource)
{
  core::OccupancyGrid grid;
  grid.width = 5;
  grid.height = 4;
  grid.cells.assign(20, 100);
  const std::string error = errorOf([&grid] { mapFromGrid(grid, {}, "topic /map"); });
  EXPECT_NE(error.find("topic /map"), std::string::npos) << error;
  EXPECT_NE(error.find("no free cell"), std::string::npos) << error;
}

}  // namespace
}  // namespace fdml_localization
