#include "fdml_localization/core/map/grid/grid_raster.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Uniform in [0, 1) from a 64-bit engine (exactly reproducible across standard libraries).
double uniform(std::mt19937_64& rng)
{
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}

int uniformInt(std::mt19937_64& rng, int n)
{
  return std::min(n - 1, static_cast<int>(uniform(rng) * n));
}

/// Largest number of cells rasterize() makes (1e9: about 1 GB of grid).
constexpr double kMaxRasterCells = 1e9;

/// ceil(@p cells) as an int, range-checked: at most kMaxRasterCells.
int cellCount(double cells, const char* what)
{
  if (!(cells >= 0.0 && cells <= kMaxRasterCells))
  {
    throw std::invalid_argument(std::string("rasterize: the grid's ") + what + " of " + std::to_string(cells) +
                                " cells is out of range (at most 1e9): use a coarser resolution");
  }
  return static_cast<int>(std::ceil(cells));
}

void checkOptions(const RasterizeOptions& o)
{
  if (!(std::isfinite(o.resolution) && o.resolution > 0.0))
  {
    throw std::invalid_argument("rasterize: resolution must be > 0 [m]");
  }
  if (!(std::isfinite(o.margin) && o.margin >= 0.0))
  {
    throw std::invalid_argument("rasterize: margin must be >= 0 [m]");
  }
  if (!(std::isfinite(o.wall_thickness) && o.wall_thickness >= 0.0))
  {
    throw std::invalid_argument("rasterize: wall_thickness must be >= 0 [m]");
  }
  if (!(o.boundary_noise >= 0.0 && o.boundary_noise <= 1.0))
  {
    throw std::invalid_argument("rasterize: boundary_noise must be in [0, 1]");
  }
  if (o.specks < 0 || o.islands < 0)
  {
    throw std::invalid_argument("rasterize: specks and islands must be >= 0");
  }
}

/// True when every cell of the box [x0, x1] x [y0, y1] exists and has value @p value.
bool boxIs(const OccupancyGrid& grid, int x0, int y0, int x1, int y1, std::int8_t value)
{
  for (int y = y0; y <= y1; ++y)
  {
    for (int x = x0; x <= x1; ++x)
    {
      if (!grid.inside(x, y) || grid.at(x, y) != value)
      {
        return false;
      }
    }
  }
  return true;
}

/// Puts up to @p count blobs of 1..2 x 1..2 cells of @p paint where a 2-cell ring around
/// the blob holds only @p background.
void addBlobs(OccupancyGrid* grid, int count, std::int8_t background, std::int8_t paint, std::mt19937_64& rng)
{
  int placed = 0;
  for (int attempt = 0; attempt < 200 * count && placed < count; ++attempt)
  {
    const int x = uniformInt(rng, grid->width);
    const int y = uniformInt(rng, grid->height);
    const int sx = 1 + uniformInt(rng, 2);
    const int sy = 1 + uniformInt(rng, 2);
    if (!boxIs(*grid, x - 2, y - 2, x + sx + 1, y + sy + 1, background))
    {
      continue;
    }
    for (int yy = y; yy < y + sy; ++yy)
    {
      for (int xx = x; xx < x + sx; ++xx)
      {
        grid->at(xx, yy) = paint;
      }
    }
    ++placed;
  }
}
/// Sets every cell whose centre is inside @p rings (even-odd, scanline per row) to @p value.
void fillInside(OccupancyGrid* grid, const std::vector<Ring>& rings, std::int8_t value)
{
  const double res = grid->resolution;
  std::vector<double> xs;
  for (int iy = 0; iy < grid->height; ++iy)
  {
    const double y = grid->origin.y + (iy + 0.5) * res;
    xs.clear();
    for (const Ring& ring : rings)
    {
      for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
      {
        const Vec2& a = ring[j];
        const Vec2& b = ring[i];
        if ((a.y() > y) != (b.y() > y))
        {
          xs.push_back(a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
        }
      }
    }
    std::sort(xs.begin(), xs.end());
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2)
    {
      const int x0 = std::max(0, static_cast<int>(std::ceil((xs[k] - grid->origin.x) / res - 0.5)));
      const int x1 =
          std::min(grid->width - 1, static_cast<int>(std::ceil((xs[k + 1] - grid->origin.x) / res - 0.5)) - 1);
      for (int ix = x0; ix <= x1; ++ix)
      {
        if (value != 100 || grid->at(ix, iy) != 0)
        {
          grid->at(ix, iy) = value;
        }
      }
    }
  }
}

/// Non-free cells within @p k cells (Chebyshev) of a free cell become occupied.
void markWalls(OccupancyGrid* grid, int k)
{
  OccupancyGrid& g = *grid;
  std::vector<char> near(g.cells.size(), 0);
  std::vector<char> row_near(g.cells.size(), 0);
  for (int iy = 0; iy < g.height; ++iy)
  {
    int last_free = -1000000;
    for (int ix = 0; ix < g.width; ++ix)
    {
      last_free = g.at(ix, iy) == 0 ? ix : last_free;
      row_near[g.index(ix, iy)] = ix - last_free <= k;
    }
    last_free = 1000000;
    for (int ix = g.width - 1; ix >= 0; --ix)
    {
      last_free = g.at(ix, iy) == 0 ? ix : last_free;
      row_near[g.index(ix, iy)] |= last_free - ix <= k;
    }
  }
  for (int ix = 0; ix < g.width; ++ix)
  {
    for (int iy = 0; iy < g.height; ++iy)
    {
      for (int d = -k; d <= k && !near[g.index(ix, iy)]; ++d)
      {
        near[g.index(ix, iy)] = g.inside(ix, iy + d) && row_near[g.index(ix, iy + d)];
      }
    }
  }
  for (std::size_t i = 0; i < g.cells.size(); ++i)
  {
    if (g.cells[i] != 0 && near[i])
    {
      g.cells[i] = 100;
    }
  }
}

/// Each free cell touching an occupied one turns occupied with probability @p p.
void addBoundaryNoise(OccupancyGrid* grid, double p, std::mt19937_64& rng)
{
  std::vector<std::size_t> bumps;
  for (int iy = 1; iy + 1 < grid->height; ++iy)
  {
    for (int ix = 1; ix + 1 < grid->width; ++ix)
    {
      const OccupancyGrid& g = *grid;
      const bool touches = g.at(ix, iy) == 0 && (g.at(ix - 1, iy) == 100 || g.at(ix + 1, iy) == 100 ||
                                                 g.at(ix, iy - 1) == 100 || g.at(ix, iy + 1) == 100);
      if (touches && uniform(rng) < p)
      {
        bumps.push_back(g.index(ix, iy));
      }
    }
  }
  for (std::size_t i : bumps)
  {
    grid->cells[i] = 100;
  }
}
}  // namespace

OccupancyGrid rasterize(const PolygonMap& map, const RasterizeOptions& options)
{
  checkOptions(options);
  if (map.empty())
  {
    throw std::invalid_argument("rasterize: empty map");
  }
  const double res = options.resolution;
  OccupancyGrid grid;
  grid.resolution = res;
  const Box2& bounds = map.bounds();
  grid.origin = Pose2(bounds.min.x() - options.margin, bounds.min.y() - options.margin, 0.0);
  grid.width = cellCount((bounds.size().x() + 2.0 * options.margin) / res, "width");
  grid.height = cellCount((bounds.size().y() + 2.0 * options.margin) / res, "height");
  if (static_cast<double>(grid.width) * grid.height > kMaxRasterCells)
  {
    throw std::invalid_argument("rasterize: " + std::to_string(grid.width) + " x " + std::to_string(grid.height) +
                                " cells is too many (at most 1e9): use a coarser resolution");
  }
  grid.cells.assign(static_cast<std::size_t>(grid.width) * grid.height, -1);

  // Free cells: centre inside the free space (even-odd over every ring's edges).
  fillInside(&grid, map.rings(), 0);
  // Walls: non-free cells within wall_thickness of a free cell.
  markWalls(&grid, cellCount(options.wall_thickness / res, "wall thickness"));
  if (options.fill_obstacles)
  {
    // A floor plan: every non-free cell inside the outer boundary is occupied.
    fillInside(&grid, { map.outer() }, 100);
  }
  std::mt19937_64 rng(options.seed);
  if (options.boundary_noise > 0.0)
  {
    addBoundaryNoise(&grid, options.boundary_noise, rng);
  }
  addBlobs(&grid, options.specks, 0, 100, rng);
  addBlobs(&grid, options.islands, -1, 0, rng);
  return grid;
}

}  // namespace core
}  // namespace fdml_localization
