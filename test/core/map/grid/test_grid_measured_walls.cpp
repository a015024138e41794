// Walls where the sensor sees them: grids made from simulated laser scans of known polygons
// (like a SLAM mapper: the cell holding each hit occupied, the cells each ray crossed free),
// converted, then rays from held-out free poses cast on the converted map against the same
// rays on the true polygon. The signed error must have no systematic offset.
#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/geometry/ray_caster.h"

#include "grid_test_maps.h"
#include "localizer_test_utils.h"
#include "scan_mapping.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace core = fdml_localization::core;
using core::Vec2;
using grid_test::uniform;

namespace
{
using grid_test::kCell;
using grid_test::kMaxRange;
using grid_test::NamedMap;
using grid_test::scanGrid;
using grid_test::testMaps;

struct ErrorStats
{
  double mean = 0.0;  ///< [m]
  double sd = 0.0;    ///< [m]
  int rays = 0;
  int outliers = 0;  ///< |error| > 3 cells (a corner or an unmapped nook): not in mean and sd
};

/// Signed range errors (converted - true) of rays from held-out free poses, away from corners
/// (10 cm) and grazing walls (over 70 deg from the normal).
ErrorStats rayErrors(const core::MapRayCaster& truth, const core::MapRayCaster& converted, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  std::vector<double> errors;
  ErrorStats stats;
  while (static_cast<int>(errors.size()) + stats.outliers < 4000)
  {
    const core::Pose2 pose = core::test::randomFreePose(truth, rng, 0.2);
    const Vec2 dir(std::cos(pose.theta), std::sin(pose.theta));
    const core::RayHit hit = truth.cast(pose.position(), dir, kMaxRange);
    if (!hit.hit())
    {
      continue;
    }
    const core::Segment& wall = truth.map().edges()[static_cast<std::size_t>(hit.segment)];
    const Vec2 at = pose.position() + hit.distance * dir;
    const Vec2 along = (wall.b - wall.a).normalized();
    if ((at - wall.a).norm() < 0.1 || (at - wall.b).norm() < 0.1 || std::abs(along.dot(dir)) > std::sin(1.2217))
    {
      continue;
    }
    const double error = converted.range(pose, kMaxRange + 1.0) - hit.distance;
    std::abs(error) > 3 * kCell ? ++stats.outliers : (errors.push_back(error), 0);
  }
  stats.rays = static_cast<int>(errors.size());
  for (double e : errors)
  {
    stats.mean += e / stats.rays;
  }
  for (double e : errors)
  {
    stats.sd += (e - stats.mean) * (e - stats.mean) / stats.rays;
  }
  stats.sd = std::sqrt(stats.sd);
  return stats;
}

/// Signed errors on the grid converted with @p walls and simplification @p tolerance [m].
ErrorStats convertAndCompare(const core::MapRayCaster& truth, const core::OccupancyGrid& grid, core::GridWalls walls,
                             double tolerance)
{
  core::GridConversionOptions options;
  options.walls = walls;
  options.tolerance = tolerance;
  const core::MapRayCaster converted(core::gridToPolygon(grid, options, "scan grid"));
  EXPECT_EQ(converted.map().holeCount(), truth.map().holeCount());
  return rayErrors(truth, converted, 99);
}

/// Pools per-grid statistics (equal ray counts) into one mean and spread.
struct Pool
{
  double sum = 0.0;
  double sum_sq = 0.0;  ///< sum of (sd^2 + mean^2) over grids
  int grids = 0;
  void add(const ErrorStats& s)
  {
    sum += s.mean;
    sum_sq += s.sd * s.sd + s.mean * s.mean;
    ++grids;
  }
  double mean() const
  {
    return sum / grids;
  }
  double sd() const
  {
    return std::sqrt(sum_sq / grids - mean() * mean());
  }
};
}  // namespace

// The wall's position within its cells differs from grid to grid (for an axis-aligned wall it
// is the same all along), so the mean is taken over four maps, three grid phases each.
TEST(MeasuredWalls, ScanMadeGridsConvertWithoutOffset)
{
  for (double tolerance : { 1e-9, 0.0 })
  {
    Pool measured;
    Pool edges;
    for (const NamedMap& named : testMaps())
    {
      const core::MapRayCaster truth(named.map);
      for (std::uint64_t phase = 1; phase <= 3; ++phase)
      {
        const core::OccupancyGrid grid = scanGrid(truth, 60, phase);
        const ErrorStats m = convertAndCompare(truth, grid, core::GridWalls::Measured, tolerance);
        const ErrorStats e = convertAndCompare(truth, grid, core::GridWalls::CellEdges, tolerance);
        std::cout << named.name << " phase " << phase << (tolerance > 0 ? " unsimplified" : " simplified")
                  << ": signed error [cm] measured " << 100 * m.mean << " +- " << 100 * m.sd << " (" << m.outliers
                  << " outliers), cell edges " << 100 * e.mean << " +- " << 100 * e.sd << "\n";
        EXPECT_LT(std::abs(m.mean), 0.015) << named.name << " phase " << phase;
        EXPECT_LT(m.outliers, 0.01 * (m.rays + m.outliers)) << named.name;
        measured.add(m);
        edges.add(e);
      }
    }
    std::cout << (tolerance > 0 ? "unsimplified" : "simplified (1 cell)") << ": measured " << 100 * measured.mean()
              << " +- " << 100 * measured.sd() << " cm, cell edges " << 100 * edges.mean() << " +- " << 100 * edges.sd()
              << " cm\n";
    EXPECT_LT(std::abs(measured.mean()), 0.005);
    EXPECT_LT(measured.sd(), 0.025);
    // Today's conversion (the free cells' edges) puts the walls in front of the hits.
    EXPECT_LT(edges.mean(), -0.02);
  }
}
