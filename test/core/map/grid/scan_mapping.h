// Shared by the grid tests: grids made the way a SLAM mapper makes them, from simulated laser
// scans of known polygon maps (the cell holding each hit occupied, the cells each beam crossed
// free, everything else unknown).
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/core/map/grid/occupancy_grid.h"

#include "grid_test_maps.h"
#include "localizer_test_utils.h"

#include <Eigen/Geometry>

#include <cmath>
#include <random>
#include <vector>

namespace grid_test
{
using core::Vec2;

constexpr double kCell = 0.05;      ///< grid cell [m]
constexpr double kMaxRange = 10.0;  ///< scan range [m]

inline core::Ring rotated(const core::Ring& ring, double angle, const Vec2& shift)
{
  const Eigen::Rotation2Dd r(angle);
  core::Ring out;
  for (const Vec2& p : ring)
  {
    out.push_back(r * p + shift);
  }
  return out;
}

/// A named test map.
struct NamedMap
{
  const char* name;
  core::PolygonMap map;
};

/// Four rooms at different angles and off the grid's lattice, with obstacles.
inline std::vector<NamedMap> testMaps()
{
  const core::Ring room = { { 0, 0 }, { 6, 0 }, { 6, 4 }, { 0, 4 } };
  const core::Ring pillar = { { 2, 1.5 }, { 2.6, 1.5 }, { 2.6, 2.2 }, { 2, 2.2 } };
  const core::Ring hexagon = { { 0, 0 }, { 4, -0.7 }, { 6.5, 1.5 }, { 5.5, 5 }, { 2, 5.5 }, { -0.8, 3 } };
  const core::Ring triangle = { { 2, 2 }, { 3.5, 2.4 }, { 2.6, 3.4 } };
  const core::Ring ell = { { 0, 0 }, { 7, 0 }, { 7, 3 }, { 3, 3 }, { 3, 6 }, { 0, 6 } };
  const core::Ring column = { { 1, 1 }, { 1.7, 1 }, { 1.7, 1.4 }, { 1, 1.4 } };
  return {
    { "room", core::PolygonMap::fromRings({ room, pillar }) },
    { "rotated room",
      core::PolygonMap::fromRings({ rotated(room, 0.31, { 0.013, 0.021 }), rotated(pillar, 0.31, { 0.013, 0.021 }) }) },
    { "hexagon", core::PolygonMap::fromRings({ hexagon, triangle }) },
    { "L",
      core::PolygonMap::fromRings({ rotated(ell, -0.52, { 0.037, 3.6 }), rotated(column, -0.52, { 0.037, 3.6 }) }) },
  };
}

/// Hit and pass counts per cell of a grid covering @p map with a margin.
struct ScanGrid
{
  core::OccupancyGrid grid;
  std::vector<int> hits;
  std::vector<int> passes;

  ScanGrid(const core::PolygonMap& map, double phase)
  {
    grid.resolution = kCell;
    grid.origin = core::Pose2(map.bounds().min.x() - 0.5 - phase, map.bounds().min.y() - 0.5 - 0.7 * phase, 0.0);
    grid.width = static_cast<int>(std::ceil((map.bounds().size().x() + 1.0) / kCell)) + 1;
    grid.height = static_cast<int>(std::ceil((map.bounds().size().y() + 1.0) / kCell)) + 1;
    hits.assign(static_cast<std::size_t>(grid.width) * grid.height, 0);
    passes = hits;
  }

  /// Marks the cells from @p from to @p to free (Amanatides-Woo) and the cell of @p to hit.
  void addRay(const Vec2& from, const Vec2& to)
  {
    const Vec2 a = grid.toLocal(from) / kCell;
    const Vec2 b = grid.toLocal(to) / kCell;
    const Vec2 d = b - a;
    int ix = static_cast<int>(std::floor(a.x()));
    int iy = static_cast<int>(std::floor(a.y()));
    const int ex = static_cast<int>(std::floor(b.x()));
    const int ey = static_cast<int>(std::floor(b.y()));
    const int sx = d.x() > 0 ? 1 : -1;
    const int sy = d.y() > 0 ? 1 : -1;
    double tx = d.x() != 0 ? ((ix + (d.x() > 0)) - a.x()) / d.x() : core::kInf;
    double ty = d.y() != 0 ? ((iy + (d.y() > 0)) - a.y()) / d.y() : core::kInf;
    const double ddx = d.x() != 0 ? 1.0 / std::abs(d.x()) : core::kInf;
    const double ddy = d.y() != 0 ? 1.0 / std::abs(d.y()) : core::kInf;
    while (!(ix == ex && iy == ey) && std::min(tx, ty) < 1.0)
    {
      ++passes[grid.index(ix, iy)];
      (tx < ty) ? (tx += ddx, ix += sx) : (ty += ddy, iy += sy);
    }
    ++hits[grid.index(ex, ey)];
  }

  /// Occupied where anything was hit, free where rays only passed, unknown elsewhere.
  core::OccupancyGrid finish()
  {
    grid.cells.assign(hits.size(), -1);
    for (std::size_t i = 0; i < hits.size(); ++i)
    {
      grid.cells[i] = hits[i] > 0 ? 100 : (passes[i] > 0 ? 0 : -1);
    }
    return grid;
  }
};

/// A grid from 360-beam scans at @p poses mapping poses (seed @p seed).
inline core::OccupancyGrid scanGrid(const core::MapRayCaster& truth, int poses, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  ScanGrid scans(truth.map(), kCell * uniform(rng));
  for (int k = 0; k < poses; ++k)
  {
    const core::Pose2 pose = fdml_localization::core::test::randomFreePose(truth, rng, 0.3);
    for (int beam = 0; beam < 360; ++beam)
    {
      const double angle = pose.theta + core::kTwoPi * beam / 360.0;
      const Vec2 dir(std::cos(angle), std::sin(angle));
      const core::RayHit hit = truth.cast(pose.position(), dir, kMaxRange);
      if (hit.hit())
      {
        scans.addRay(pose.position(), pose.position() + hit.distance * dir);
      }
    }
  }
  return scans.finish();
}

}  // namespace grid_test
