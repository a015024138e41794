#include "fdml_localization/core/map/grid/grid_to_polygon.h"

#include "fdml_localization/core/map/grid/grid_trace.h"

#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/map/ring_simplify.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
std::string formatPoint(const Vec2& p)
{
  std::ostringstream s;
  s << "(" << p.x() << ", " << p.y() << ")";
  return s.str();
}

/// Labels the 4-connected components of the free mask (label -1: not free).
int labelRegions(const std::vector<char>& free, int width, int height, std::vector<int>* labels,
                 std::vector<long>* sizes)
{
  labels->assign(free.size(), -1);
  sizes->clear();
  std::vector<int> stack;
  for (std::size_t start = 0; start < free.size(); ++start)
  {
    if (!free[start] || (*labels)[start] >= 0)
    {
      continue;
    }
    const int label = static_cast<int>(sizes->size());
    long count = 0;
    stack.assign(1, static_cast<int>(start));
    (*labels)[start] = label;
    while (!stack.empty())
    {
      const int idx = stack.back();
      stack.pop_back();
      ++count;
      const int x = idx % width;
      const int y = idx / width;
      const int neighbours[4][2] = { { x - 1, y }, { x + 1, y }, { x, y - 1 }, { x, y + 1 } };
      for (const auto& n : neighbours)
      {
        if (n[0] < 0 || n[1] < 0 || n[0] >= width || n[1] >= height)
        {
          continue;
        }
        const int nidx = n[1] * width + n[0];
        if (free[nidx] && (*labels)[nidx] < 0)
        {
          (*labels)[nidx] = label;
          stack.push_back(nidx);
        }
      }
    }
    sizes->push_back(count);
  }
  return static_cast<int>(sizes->size());
}

void checkOptions(const GridConversionOptions& options, const std::string& source)
{
  if (!std::isfinite(options.tolerance))
  {
    throw MapError(source, 0, "conversion tolerance must be finite [m] (<= 0: one cell)");
  }
  if (!std::isfinite(options.min_area))
  {
    throw MapError(source, 0, "conversion min_area must be finite [m^2] (< 0: ten cells)");
  }
  if (options.occupied_threshold < 1 || options.occupied_threshold > 100)
  {
    throw MapError(source, 0,
                   "occupied_threshold must be in [1, 100] (got " + std::to_string(options.occupied_threshold) + ")");
  }
  if (options.walls != GridWalls::Measured && options.walls != GridWalls::CellEdges)
  {
    throw MapError(source, 0, "conversion walls must be measured or cell_edges");
  }
  if (options.use_seed && !(std::isfinite(options.seed_point.x()) && std::isfinite(options.seed_point.y())))
  {
    throw MapError(source, 0, "seed point must be finite");
  }
}

/// The free mask (counted into @p info) and the free region to keep (its label's cells).
std::vector<char> chooseRegion(const OccupancyGrid& grid, const GridConversionOptions& options,
                               const std::string& source, GridConversionReport* info)
{
  std::vector<char> free(grid.cells.size(), 0);
  for (std::size_t i = 0; i < grid.cells.size(); ++i)
  {
    free[i] = grid.cells[i] >= 0 && grid.cells[i] < options.occupied_threshold;
    info->free_cells += free[i];
  }
  if (info->free_cells == 0)
  {
    throw MapError(source, 0,
                   "no free cell in the " + std::to_string(grid.width) + " x " + std::to_string(grid.height) +
                       " grid (every cell is occupied or unknown): nothing to localize in");
  }
  std::vector<int> labels;
  std::vector<long> sizes;
  info->regions = labelRegions(free, grid.width, grid.height, &labels, &sizes);
  int chosen = static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  if (options.use_seed)
  {
    int ix = 0;
    int iy = 0;
    if (!grid.cellOf(options.seed_point, &ix, &iy))
    {
      throw MapError(source, 0, "seed point " + formatPoint(options.seed_point) + " lies outside the grid");
    }
    chosen = labels[grid.index(ix, iy)];
    if (chosen < 0)
    {
      throw MapError(source, 0,
                     "seed point " + formatPoint(options.seed_point) + " lies in a " +
                         (grid.at(ix, iy) < 0 ? "unknown" : "occupied") + " cell (" + std::to_string(ix) + ", " +
                         std::to_string(iy) + ") of value " + std::to_string(grid.at(ix, iy)));
    }
  }
  info->region_cells = sizes[chosen];
  for (std::size_t i = 0; i < labels.size(); ++i)
  {
    free[i] = labels[i] == chosen;
  }
  return free;
}

/**
 * The region's rings in cell units: the outer boundary first (the counter-clockwise ring of
 * largest area), then every hole (clockwise) of at least @p min_area_cells. Areas are those of
 * the cell-edge rings (cells enclosed), whatever the walls' offset.
 */
std::vector<Ring> regionRings(const std::vector<char>& region, int width, int height, GridWalls walls,
                              double min_area_cells, GridConversionReport* info)
{
  const std::vector<Ring> edges = traceRegionBoundaries(region, width, height, 0.0);
  std::vector<Ring> shifted;
  if (walls == GridWalls::Measured)
  {
    shifted = traceRegionBoundaries(region, width, height, kMeasuredWallOffset);
  }
  const std::vector<Ring>& traced = walls == GridWalls::Measured ? shifted : edges;
  std::size_t outer = 0;
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    outer = signedArea(edges[i]) > signedArea(edges[outer]) ? i : outer;
  }
  std::vector<Ring> rings{ traced[outer] };
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    const double area = signedArea(edges[i]);
    if (i == outer || area >= 0.0)
    {
      continue;  // the outer ring; no other ring of a 4-connected region is counter-clockwise
    }
    ++info->holes_found;
    if (-area < min_area_cells)
    {
      ++info->holes_dropped;
      continue;
    }
    rings.push_back(traced[i]);
  }
  return rings;
}
}  // namespace

GridWalls parseGridWalls(const std::string& text)
{
  if (text == "measured")
  {
    return GridWalls::Measured;
  }
  if (text == "cell_edges")
  {
    return GridWalls::CellEdges;
  }
  throw std::invalid_argument("unknown grid walls '" + text + "' (allowed: measured, cell_edges)");
}

const char* toString(GridWalls walls)
{
  return walls == GridWalls::CellEdges ? "cell_edges" : "measured";
}

PolygonMap gridToPolygon(const OccupancyGrid& grid, const GridConversionOptions& options, const std::string& source,
                         GridConversionReport* report)
{
  const std::vector<std::string> issues = grid.validate();
  if (!issues.empty())
  {
    throw MapError(source, 0, "invalid occupancy grid: " + issues.front());
  }
  checkOptions(options, source);
  GridConversionReport info;
  const double res = grid.resolution;
  info.tolerance_used = options.tolerance > 0.0 ? options.tolerance : res;
  info.min_area_used = options.min_area >= 0.0 ? options.min_area : 10.0 * res * res;
  const std::vector<char> region = chooseRegion(grid, options, source, &info);
  const std::vector<Ring> rings =
      regionRings(region, grid.width, grid.height, options.walls, info.min_area_used / (res * res), &info);
  // Simplify in cell units, where every traced vertex is a multiple of 1/32 cell, so the
  // touching and crossing tests are exact; then scale and apply the origin pose.
  for (const Ring& ring : rings)
  {
    info.vertices_traced += static_cast<long>(ring.size());
  }
  SimplifyStats stats;
  std::vector<Ring> simple = simplifyRings(rings, info.tolerance_used / res, &stats);
  info.rings_tightened = stats.rings_tightened;
  for (Ring& ring : simple)
  {
    info.vertices_kept += static_cast<long>(ring.size());
    for (Vec2& p : ring)
    {
      p = grid.toMap(p * res);
    }
  }
  if (report != nullptr)
  {
    *report = info;
  }
  return PolygonMap::fromRings(std::move(simple), source);
}

}  // namespace core
}  // namespace fdml_localization
