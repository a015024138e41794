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
  EXPECT_NE(format.find("unsupported map format"), std::string::npos) << format;

  const std::string path = "/tmp/fdml_map_loading_test_" + std::to_string(::getpid()) + ".poly";
  FILE* file = std::fopen(path.c_str(), "w");
  ASSERT_NE(file, nullptr);
  std::fputs("0 0\n1 0\n", file);  // one ring of two vertices
  std::fclose(file);
  const std::string invalid = errorOf([&path] { loadMap(path); });
  std::remove(path.c_str());
  EXPECT_NE(invalid.find(path), std::string::npos) << invalid;
}

}  // namespace
}  // namespace fdml_localization
