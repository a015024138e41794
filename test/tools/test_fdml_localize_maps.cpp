// fdml_localize takes every map the core loads (a .poly, a map_server .yaml, a .poly converted
// from a grid), and a map from a grid gets the grid tolerances unless they are given.
#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/core/map/grid/grid_tolerances.h"
#include "fdml_localization/io/map_files.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
namespace fs = std::filesystem;

struct Best
{
  int status = -1;
  Pose2 pose;
  int inliers = -1;
};

/// Runs fdml_localize with @p args and parses its best candidate.
Best runLocalize(const std::string& args, const fs::path& dir)
{
  const std::string out = (dir / "out.txt").string();
  const int status = std::system(
      (std::string(FDML_LOCALIZE_EXE) + " " + args + " > " + out + " 2> " + (dir / "err.txt").string()).c_str());
  Best best;
  best.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(out);
  std::string line;
  std::getline(in, line);  // header
  char comma = 0;
  int rank = 0;
  if (in >> rank >> comma >> best.pose.x >> comma >> best.pose.y >> comma >> best.pose.theta >> comma >> best.inliers)
  {
    return best;
  }
  best.inliers = -1;
  return best;
}
}  // namespace

TEST(LocalizeMaps, PolyYamlAndConvertedPolyAlikeWithGridTolerances)
{
  const fs::path dir = fs::temp_directory_path() / ("fdml_localize_maps_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const auto room = test::lRoomMap();  // walls on multiples of 5 cm: on the grid's cell edges
  savePolyFile((dir / "room.poly").string(), room->map());
  io::saveOccupancyGridYaml((dir / "room.yaml").string(), rasterize(room->map(), RasterizeOptions{}));
  const io::MapFile converted = io::readMapFile((dir / "room.yaml").string());
  savePolyFile((dir / "converted.poly").string(), converted.map, cellSizeHeader(converted.cell_size));

  // Ten exact readings, two opposite ones (nearly across the room, between parallel walls) 7 cm
  // short each. A shifted pose trades one's error for the other's, so the pair needs a chord
  // 14 cm shorter than the wall-to-wall one: beyond twice the default 5 cm agreement tolerance
  // on the polygon (9 inliers at best), within twice the 10 cm of a 5 cm grid (whose walls lie
  // 2.3 cm beyond the plan's: 10 inliers). One short reading alone would not do: a pose 1 cm off
  // explains it within 5 cm.
  const Pose2 truth(6.1, 3.2, -0.4);
  std::vector<Reading> readings = test::exactReadings(*room, truth, test::inPlaceOffsets(10));
  readings[3].range -= 0.07;
  readings[8].range -= 0.07;  // 3 pi / 5 rad + pi: the opposite direction
  std::ofstream csv(dir / "r.csv");
  csv.precision(17);
  csv << "gx,gy,gtheta,d\n";
  for (const Reading& r : readings)
  {
    csv << r.offset.x << "," << r.offset.y << "," << r.offset.theta << "," << r.range << "\n";
  }
  csv.close();
  const std::string csv_path = (dir / "r.csv").string();
  struct Case
  {
    std::string args;
    int inliers;
  };
  const Case cases[] = {
    { "--map " + (dir / "room.poly").string(), 9 },
    { "--map " + (dir / "room.yaml").string(), 10 },
    { "--map " + (dir / "converted.poly").string(), 10 },
    // As given: the grid's walls 2.3 cm beyond the plan's lengthen every chord, and a pose about
    // 5 cm off explains 9 (both engines find it since the region fill searches leaves that may
    // beat the best candidate; the adaptive engine's certificate bounds the consensus at 9).
    { "--map " + (dir / "room.yaml").string() + " --tolerance 0.05", 9 },
  };
  for (const Case& c : cases)
  {
    // The voxel engine: its search goes down from the readings agreeing within the agreement
    // tolerance, which these counts are about (the adaptive engine proves the consensus within
    // the smaller range tolerance, 9 here, and may stop at a pose of 9 inliers).
    const Best best = runLocalize("--engine voxel " + c.args + " " + csv_path, dir);
    EXPECT_EQ(best.status, 0) << c.args;
    EXPECT_LT(test::positionError(best.pose, truth), 0.07) << c.args;  // the readings' 7 cm error
    EXPECT_EQ(best.inliers, c.inliers) << c.args;
  }
  fs::remove_all(dir);
}

TEST(LocalizeMaps, ARegionFileBoundsTheSearch)
{
  const fs::path dir = fs::temp_directory_path() / ("fdml_localize_region_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  // Rooms [0, 4] x [0, 3] and [6, 10] x [0, 3], joined by a band along y in [3, 3.5]: a pose in
  // one and its copy 6 m to the right read alike.
  const Ring outer = { { 0, 0 }, { 4, 0 }, { 4, 3 }, { 6, 3 }, { 6, 0 }, { 10, 0 }, { 10, 3.5 }, { 0, 3.5 } };
  const MapRayCaster map(PolygonMap::fromRings({ outer }));
  savePolyFile((dir / "rooms.poly").string(), map.map());
  const auto rectangle = [](double x0, double x1) {
    return PolygonMap::fromRings({ Ring{ { x0, 0 }, { x1, 0 }, { x1, 3 }, { x0, 3 } } });
  };
  savePolyFile((dir / "left.poly").string(), rectangle(0.0, 4.0));
  savePolyFile((dir / "right.poly").string(), rectangle(6.0, 10.0));
  savePolyFile((dir / "away.poly").string(), rectangle(20.0, 24.0));
  // The right room as a map_server grid region (the free region holding the seed point).
  io::saveOccupancyGridYaml((dir / "right.yaml").string(), rasterize(rectangle(6.0, 10.0), RasterizeOptions{}));
  const Pose2 truth(1.5, 1.0, 0.3);
  const Pose2 twin(7.5, 1.0, 0.3);
  std::ofstream csv(dir / "r.csv");
  csv.precision(17);
  csv << "gx,gy,gtheta,d\n";
  for (const Reading& r : test::exactReadings(map, truth, test::inPlaceOffsets(8)))
  {
    csv << r.offset.x << "," << r.offset.y << "," << r.offset.theta << "," << r.range << "\n";
  }
  csv.close();
  const std::string base = "--map " + (dir / "rooms.poly").string() + " " + (dir / "r.csv").string();
  for (const char* engine : { "voxel", "adaptive" })
  {
    const std::string with = base + " --engine " + engine + " --region ";
    const Best left = runLocalize(with + (dir / "left.poly").string(), dir);
    EXPECT_EQ(left.status, 0) << engine;
    EXPECT_LT(test::positionError(left.pose, truth), 0.05) << engine;
    for (const std::string& region : { (dir / "right.poly").string(), (dir / "right.yaml").string() + " --region-seed "
                                                                                                      "8,1" })
    {
      const Best right = runLocalize(with + region, dir);
      EXPECT_EQ(right.status, 0) << engine << " " << region;
      EXPECT_LT(test::positionError(right.pose, twin), 0.05) << engine << " " << region;
    }
    EXPECT_EQ(runLocalize(with + (dir / "away.poly").string(), dir).status, 2) << engine;
  }
  EXPECT_EQ(runLocalize(base + " --region-seed 8,1", dir).status, 2);
  EXPECT_EQ(runLocalize(base + " --region " + (dir / "missing.poly").string(), dir).status, 2);
  fs::remove_all(dir);
}

}  // namespace core
}  // namespace fdml_localization
