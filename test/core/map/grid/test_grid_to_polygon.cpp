// Occupancy grid -> polygon: exact tracing, validity under simplification, specks, seeds,
// and ray casts on the converted polygon against an independent ray walk on the grid.
#include "fdml_localization/core/map/grid/grid_to_polygon.h"

#include "grid_test_maps.h"
#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/io/map_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace core = fdml_localization::core;
namespace io = fdml_localization::io;
using core::Vec2;
using grid_test::officeMap;
using grid_test::uniform;

namespace
{
std::vector<char> freeMask(const core::OccupancyGrid& g, int threshold = 50)
{
  std::vector<char> free(g.cells.size());
  for (std::size_t i = 0; i < g.cells.size(); ++i)
  {
    free[i] = g.cells[i] >= 0 && g.cells[i] < threshold;
  }
  return free;
}

/// The largest 4-connected free region (independent flood fill).
std::vector<char> largestRegion(const core::OccupancyGrid& g)
{
  const std::vector<char> free = freeMask(g);
  std::vector<int> label(free.size(), -1);
  std::vector<long> size;
  for (std::size_t s = 0; s < free.size(); ++s)
  {
    if (!free[s] || label[s] >= 0)
    {
      continue;
    }
    const int l = static_cast<int>(size.size());
    size.push_back(0);
    std::vector<std::size_t> stack{ s };
    label[s] = l;
    while (!stack.empty())
    {
      const std::size_t i = stack.back();
      stack.pop_back();
      ++size[l];
      const int x = static_cast<int>(i % g.width);
      const int y = static_cast<int>(i / g.width);
      for (const auto& d : { std::pair<int, int>{ 1, 0 }, { -1, 0 }, { 0, 1 }, { 0, -1 } })
      {
        if (g.inside(x + d.first, y + d.second))
        {
          const std::size_t j = g.index(x + d.first, y + d.second);
          if (free[j] && label[j] < 0)
          {
            label[j] = l;
            stack.push_back(j);
          }
        }
      }
    }
  }
  const int best = static_cast<int>(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<char> region(free.size());
  for (std::size_t i = 0; i < free.size(); ++i)
  {
    region[i] = label[i] == best;
  }
  return region;
}

/// Reference ray walk on the grid (Amanatides-Woo): distance [m] from @p p along map angle
/// @p angle to the first cell that is not free (or the grid's edge).
double gridCast(const core::OccupancyGrid& g, const std::vector<char>& free, const Vec2& p, double angle)
{
  const Vec2 o = g.toLocal(p) / g.resolution;
  const double a = angle - g.origin.theta;
  const double dx = std::cos(a);
  const double dy = std::sin(a);
  int ix = static_cast<int>(std::floor(o.x()));
  int iy = static_cast<int>(std::floor(o.y()));
  const int sx = dx > 0 ? 1 : -1;
  const int sy = dy > 0 ? 1 : -1;
  const double inf = core::kInf;
  double tx = dx != 0 ? ((ix + (dx > 0)) - o.x()) / dx : inf;
  double ty = dy != 0 ? ((iy + (dy > 0)) - o.y()) / dy : inf;
  const double ddx = dx != 0 ? 1.0 / std::abs(dx) : inf;
  const double ddy = dy != 0 ? 1.0 / std::abs(dy) : inf;
  double t = 0.0;
  while (g.inside(ix, iy) && free[g.index(ix, iy)])
  {
    if (tx < ty)
    {
      t = tx;
      tx += ddx;
      ix += sx;
    }
    else
    {
      t = ty;
      ty += ddy;
      iy += sy;
    }
  }
  return t * g.resolution;
}

/// A random grid: each cell occupied with probability @p p_wall, border cells unknown.
core::OccupancyGrid randomGrid(int w, int h, double p_wall, std::uint64_t seed, const core::Pose2& origin)
{
  std::mt19937_64 rng(seed);
  core::OccupancyGrid g;
  g.width = w;
  g.height = h;
  g.resolution = 0.1;
  g.origin = origin;
  for (int i = 0; i < w * h; ++i)
  {
    g.cells.push_back(static_cast<std::int8_t>(uniform(rng) < p_wall ? 100 : 0));
  }
  return g;
}

struct RayStats
{
  double within_one_cell = 0.0;  ///< fraction of rays within 1 cell
  double within_two_cells = 0.0;
  double median_cells = 0.0;
};

RayStats compareRays(const core::OccupancyGrid& g, const core::PolygonMap& map, int rays, std::uint64_t seed)
{
  const core::MapRayCaster caster(map);
  const std::vector<char> free = freeMask(g);
  const std::vector<char> region = largestRegion(g);
  std::vector<std::size_t> cells;
  for (std::size_t i = 0; i < region.size(); ++i)
  {
    if (region[i])
    {
      cells.push_back(i);
    }
  }
  std::mt19937_64 rng(seed);
  std::vector<double> errors;
  for (int r = 0; r < rays; ++r)
  {
    const std::size_t c = cells[static_cast<std::size_t>(uniform(rng) * cells.size())];
    const int ix = static_cast<int>(c % g.width);
    const int iy = static_cast<int>(c / g.width);
    const Vec2 p = g.toMap(Vec2((ix + uniform(rng)) * g.resolution, (iy + uniform(rng)) * g.resolution));
    const double angle = core::kTwoPi * uniform(rng);
    const double on_grid = gridCast(g, free, p, angle);
    const double on_polygon = caster.range(core::Pose2(p.x(), p.y(), angle));
    errors.push_back(std::abs(on_grid - on_polygon) / g.resolution);
  }
  RayStats stats;
  stats.within_one_cell = std::count_if(errors.begin(), errors.end(), [](double e) { return e <= 1.0; }) /
                          static_cast<double>(errors.size());
  stats.within_two_cells = std::count_if(errors.begin(), errors.end(), [](double e) { return e <= 2.0; }) /
                           static_cast<double>(errors.size());
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  stats.median_cells = errors[errors.size() / 2];
  return stats;
}

/// Unsimplified, walls on the cell edges: the tracing itself.
core::GridConversionOptions exact()
{
  core::GridConversionOptions o;
  o.walls = core::GridWalls::CellEdges;
  o.tolerance = 1e-9;
  o.min_area = 0.0;
  return o;
}
}  // namespace

TEST(GridToPolygon, RectangleRoomFollowsTheCellEdges)
{
  core::OccupancyGrid g;
  g.width = 12;
  g.height = 9;
  g.resolution = 0.1;
  g.origin = core::Pose2(1.0, 2.0, 0.0);
  g.cells.assign(108, -1);
  for (int iy = 3; iy <= 5; ++iy)
  {
    for (int ix = 2; ix <= 7; ++ix)
    {
      g.at(ix, iy) = 0;
    }
  }
  g.at(4, 4) = 100;  // a one-cell pillar
  const core::PolygonMap map = core::gridToPolygon(g, exact());
  ASSERT_EQ(map.holeCount(), 1u);
  EXPECT_EQ(map.outer().size(), 4u);
  EXPECT_EQ(map.rings()[1].size(), 4u);
  EXPECT_NEAR(map.bounds().min.x(), 1.2, 1e-12);
  EXPECT_NEAR(map.bounds().max.x(), 1.8, 1e-12);
  EXPECT_NEAR(map.bounds().min.y(), 2.3, 1e-12);
  EXPECT_NEAR(map.bounds().max.y(), 2.6, 1e-12);
  EXPECT_NEAR(map.area(), 17 * 0.01, 1e-12);
}

TEST(GridToPolygon, DiagonalWallContactsStayClosed)
{
  // Free cells touching only at corners must not leak through: a checkerboard of walls in a
  // 7 x 7 room keeps every free cell its own region, and the seed's region is one cell.
  core::OccupancyGrid g;
  g.width = 7;
  g.height = 7;
  g.resolution = 1.0;
  for (int iy = 0; iy < 7; ++iy)
  {
    for (int ix = 0; ix < 7; ++ix)
    {
      g.cells.push_back(static_cast<std::int8_t>((ix + iy) % 2 == 0 ? 0 : 100));
    }
  }
  core::GridConversionOptions options = exact();
  options.use_seed = true;
  options.seed_point = Vec2(3.5, 3.5);
  core::GridConversionReport report;
  const core::PolygonMap map = core::gridToPolygon(g, options, "checkerboard", &report);
  EXPECT_EQ(report.regions, 25);
  EXPECT_EQ(report.region_cells, 1);
  // Its diagonal neighbours are other regions, i.e. walls for this one: a plain square.
  EXPECT_NEAR(map.area(), 1.0, 1e-12);
  EXPECT_EQ(map.outer().size(), 4u);
  // A region touching itself diagonally around a pair of wall cells that meet at a corner:
  // the two walls form one closed hole, the region loses a 1/8-cell chamfer on each side.
  core::OccupancyGrid pinch;
  pinch.width = 4;
  pinch.height = 4;
  pinch.resolution = 1.0;
  pinch.cells.assign(16, 0);
  pinch.at(2, 1) = 100;
  pinch.at(1, 2) = 100;
  const core::PolygonMap pinched = core::gridToPolygon(pinch, exact(), "pinch", &report);
  EXPECT_EQ(report.regions, 1);
  ASSERT_EQ(pinched.holeCount(), 1u);
  EXPECT_NEAR(pinched.area(), 16.0 - 2.0 - 2 * 0.5 * 0.125 * 0.125, 1e-12);
  EXPECT_FALSE(pinched.containsBruteForce(Vec2(2.0, 2.0)));  // the wall's corner contact
  EXPECT_TRUE(pinched.containsBruteForce(Vec2(1.8, 1.8)));
}

TEST(GridToPolygon, CellCentresAreInsideExactlyForTheRegionOnNoisyRotatedGrids)
{
  // 35 % random walls: thousands of saddles (diagonal contacts), islands and holes.
  for (std::uint64_t seed = 1; seed <= 4; ++seed)
  {
    const core::OccupancyGrid g = randomGrid(50, 40, 0.35, seed, core::Pose2(-3.0, 2.0, 0.3 * seed));
    core::GridConversionReport report;
    const core::PolygonMap map = core::gridToPolygon(g, exact(), "random", &report);
    const std::vector<char> region = largestRegion(g);
    EXPECT_EQ(report.region_cells, std::count(region.begin(), region.end(), 1));
    EXPECT_EQ(report.rings_tightened, 0);
    int wrong = 0;
    for (int iy = 0; iy < g.height; ++iy)
    {
      for (int ix = 0; ix < g.width; ++ix)
      {
        wrong += map.containsBruteForce(g.cellCentre(ix, iy)) != static_cast<bool>(region[g.index(ix, iy)]);
      }
    }
    EXPECT_EQ(wrong, 0) << "seed " << seed;
  }
}

TEST(GridToPolygon, DefaultSimplificationStaysValidAndCloseOnNoisyGrids)
{
  for (std::uint64_t seed = 1; seed <= 6; ++seed)
  {
    const core::OccupancyGrid g = randomGrid(80, 60, 0.3, 100 + seed, core::Pose2(0.5, -1.0, -0.2 * seed));
    core::GridConversionOptions options;
    options.min_area = 0.0;
    core::GridConversionReport report;
    core::PolygonMap map;
    ASSERT_NO_THROW(map = core::gridToPolygon(g, options, "random", &report)) << "seed " << seed;
    EXPECT_LT(report.vertices_kept, report.vertices_traced);
    EXPECT_EQ(static_cast<int>(map.holeCount()), report.holes_found);
    // A region cell whose every neighbour within 2 cells is in the region stays inside.
    const std::vector<char> region = largestRegion(g);
    int wrong = 0;
    for (int iy = 2; iy + 2 < g.height; ++iy)
    {
      for (int ix = 2; ix + 2 < g.width; ++ix)
      {
        bool deep = true;
        for (int dy = -2; dy <= 2 && deep; ++dy)
        {
          for (int dx = -2; dx <= 2 && deep; ++dx)
          {
            deep = region[g.index(ix + dx, iy + dy)];
          }
        }
        wrong += deep && !map.containsBruteForce(g.cellCentre(ix, iy));
      }
    }
    EXPECT_EQ(wrong, 0) << "seed " << seed;
  }
}

TEST(GridToPolygon, SpecksAndIslandsAreDroppedAndRoomsKept)
{
  const core::PolygonMap office = officeMap();
  core::RasterizeOptions raster;
  raster.boundary_noise = 0.15;
  raster.specks = 40;
  raster.islands = 10;
  raster.seed = 11;
  const core::OccupancyGrid g = core::rasterize(office, raster);
  core::GridConversionReport report;
  // The rasteriser frees the cells whose centre is in free space: the walls are on the edges.
  core::GridConversionOptions options;
  options.walls = core::GridWalls::CellEdges;
  const core::PolygonMap map = core::gridToPolygon(g, options, "office grid", &report);
  EXPECT_EQ(map.holeCount(), office.holeCount());
  EXPECT_GE(report.holes_dropped, 40);
  EXPECT_GE(report.regions, 11);
  // Noise bumps only take area away: within one cell of the walls' length.
  double perimeter = 0.0;
  for (const core::Segment& e : office.edges())
  {
    perimeter += (e.b - e.a).norm();
  }
  EXPECT_LT(map.area(), office.area());
  EXPECT_GT(map.area(), office.area() - perimeter * raster.resolution);
}

TEST(GridToPolygon, RayCastsAgreeWithTheGridItself)
{
  // With the walls on the cell edges and unsimplified, a ray meets the polygon where it meets
  // the first non-free cell (up to the
  // 1/8-cell chamfers at corner contacts). Simplified by one cell, noise-free walls still
  // agree; one-cell noise bumps along the walls are smoothed away, which rays at grazing
  // angles see as larger differences.
  struct Case
  {
    double noise;
    int specks;
    double tolerance;  // [m]; 0 = default (one cell)
    double min_within_one;
    double min_within_two;
  };
  const Case cases[] = {
    { 0.0, 0, 1e-9, 0.995, 0.999 }, { 0.15, 60, 1e-9, 0.995, 0.999 }, { 0.0, 0, 0.0, 0.99, 0.995 },
    { 0.0, 60, 0.0, 0.99, 0.995 },  { 0.15, 0, 0.0, 0.75, 0.93 },     { 0.15, 60, 0.0, 0.75, 0.93 },
  };
  const core::PolygonMap office = officeMap();
  for (const Case& c : cases)
  {
    core::RasterizeOptions raster;
    raster.boundary_noise = c.noise;
    raster.specks = c.specks;
    raster.seed = 5;
    core::OccupancyGrid g = core::rasterize(office, raster);
    for (double yaw : { 0.0, 0.7 })
    {
      g.origin = core::Pose2(2.0, -1.0, yaw);
      core::GridConversionOptions options;
      options.walls = core::GridWalls::CellEdges;
      options.tolerance = c.tolerance;
      options.min_area = 0.0;
      const core::PolygonMap map = core::gridToPolygon(g, options);
      EXPECT_EQ(map.holeCount(), office.holeCount() + c.specks);
      const RayStats stats = compareRays(g, map, 2000, 17);
      const std::string label = "noise " + std::to_string(c.noise) + " specks " + std::to_string(c.specks) +
                                " tolerance " + std::to_string(c.tolerance) + " yaw " + std::to_string(yaw);
      EXPECT_GE(stats.within_one_cell, c.min_within_one) << label;
      EXPECT_GE(stats.within_two_cells, c.min_within_two) << label;
      EXPECT_LE(stats.median_cells, 0.1) << label;
    }
  }
}
