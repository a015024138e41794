// The closest stand-in for real scans here: maps converted from grids made of simulated laser
// scans (scan_mapping.h), localized at the defaults plus the grid tolerances from 10 beams of
// one 180-degree laser scan at held-out poses, the ranges cast on the true polygon. With the walls
// through the wall cells the fixes must be at least as good as with the walls on the cell
// edges (the old conversion, which put every fix about 4 cm behind the truth).
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/grid/grid_tolerances.h"

#include "localizer_test_utils.h"
#include "scan_mapping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <memory>
#include <random>
#include <vector>

namespace core = fdml_localization::core;

namespace
{
struct Fixes
{
  int trials = 0;
  int within_5cm_2deg = 0;
  int within_20cm_5deg = 0;
  std::vector<double> errors;  ///< position error of the best candidate [m] (1 m when none)

  double median()
  {
    std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
    return errors[errors.size() / 2];
  }
};

/// 10 beams of one scan of a laser with a 180-degree field of view (a SICK LMS).
std::vector<core::Pose2> laserFan()
{
  std::vector<core::Pose2> beams;
  for (int i = 0; i < 10; ++i)
  {
    beams.emplace_back(0.0, 0.0, -0.5 * core::kPi + core::kPi * i / 9.0);
  }
  return beams;
}

Fixes localizeOn(const core::MapRayCaster& truth, const core::OccupancyGrid& grid, core::GridWalls walls)
{
  core::GridConversionOptions conversion;
  conversion.walls = walls;
  auto map = std::make_shared<const core::MapRayCaster>(core::gridToPolygon(grid, conversion, "scan grid"));
  core::Localizer localizer(map, core::withGridTolerances({}, grid.resolution));
  std::mt19937_64 rng(2024);  // held out: not the mapping poses' stream
  Fixes fixes;
  for (int trial = 0; trial < 10; ++trial)
  {
    const core::Pose2 pose = core::test::randomFreePose(truth, rng, 0.3);
    const core::Result result = localizer.localize(core::test::exactReadings(truth, pose, laserFan()));
    double error = 1.0;
    double angle = core::kPi;
    if (!result.candidates.empty())
    {
      error = core::test::positionError(result.candidates[0].pose, pose);
      angle = std::abs(core::angleDiff(result.candidates[0].pose.theta, pose.theta));
    }
    ++fixes.trials;
    fixes.within_5cm_2deg += error < 0.05 && angle < 2.0 * core::kPi / 180.0;
    fixes.within_20cm_5deg += error < 0.2 && angle < 5.0 * core::kPi / 180.0;
    fixes.errors.push_back(error);
  }
  return fixes;
}
}  // namespace

TEST(ScanGridLocalization, WallsThroughTheWallCellsFixCloserThanCellEdges)
{
  Fixes measured_all;
  Fixes edges_all;
  for (const grid_test::NamedMap& named : grid_test::testMaps())
  {
    const core::MapRayCaster truth(named.map);
    const core::OccupancyGrid grid = grid_test::scanGrid(truth, 60, 11);
    for (auto [walls, all] : { std::make_pair(core::GridWalls::Measured, &measured_all),
                               std::make_pair(core::GridWalls::CellEdges, &edges_all) })
    {
      Fixes fixes = localizeOn(truth, grid, walls);
      std::cout << named.name << " " << core::toString(walls) << ": " << fixes.within_5cm_2deg << " / "
                << fixes.within_20cm_5deg << " of " << fixes.trials << " within 5 cm, 2 deg / 20 cm, 5 deg; median "
                << 100 * fixes.median() << " cm\n";
      all->trials += fixes.trials;
      all->within_5cm_2deg += fixes.within_5cm_2deg;
      all->within_20cm_5deg += fixes.within_20cm_5deg;
      all->errors.insert(all->errors.end(), fixes.errors.begin(), fixes.errors.end());
    }
  }
  std::cout << "measured: " << measured_all.within_5cm_2deg << " / " << measured_all.within_20cm_5deg << " of "
            << measured_all.trials << ", median " << 100 * measured_all.median() << " cm; cell edges "
            << edges_all.within_5cm_2deg << " / " << edges_all.within_20cm_5deg << ", median "
            << 100 * edges_all.median() << " cm\n";
  // Measured: 37 / 37 of 40, median 1.6 cm; cell edges 32 / 38, median 3.4 cm. The misses beyond
  // 20 cm are mirror places of these symmetric rooms seen by a half-turn scan, which either grid
  // may rank first (cell edges gained one when the leaf search went on past other leaves' places,
  // e4c8875): no comparison there, only that measured walls fix nearly every scan.
  EXPECT_GE(measured_all.within_5cm_2deg, 0.85 * measured_all.trials);
  EXPECT_GE(measured_all.within_5cm_2deg, edges_all.within_5cm_2deg + 2);
  EXPECT_GE(measured_all.within_20cm_5deg, 0.9 * measured_all.trials);
  EXPECT_LT(measured_all.median(), 0.8 * edges_all.median());
}
