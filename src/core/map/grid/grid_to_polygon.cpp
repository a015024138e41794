#include "fdml_localization/core/map/grid/grid_to_polygon.h"

#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/map/ring_simplify.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>

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

/**
 * Traces the boundary of the region along the cell edges, region on the left, so straight
 * walls lie exactly on the cell edges. At a vertex where the region touches itself only
 * diagonally (a saddle), the trace turns tightly around each cell, so the region stays
 * 4-connected and the walls 8-connected, and cuts a tiny chamfer (kChamfer cells) off each
 * of the two region corners there, so that no ring touches itself or another.
 * Returns rings in local cell units: cell (ix, iy) spans [ix, ix + 1] x [iy, iy + 1].
 */
std::vector<Ring> traceBoundaries(const std::vector<char>& region, int width, int height)
{
  constexpr double kChamfer = 0.125;  // exact in binary: keeps cell-unit arithmetic exact
  // Side s of a cell runs from its corner s to corner s + 1 (counter-clockwise: bottom, right,
  // top, left); kDir[s] is its direction and kDir[s + 1] the inward normal (the region side).
  static const int kDir[4][2] = { { 1, 0 }, { 0, 1 }, { -1, 0 }, { 0, -1 } };
  static const int kCorner[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
  auto in = [&](int x, int y) {
    return x >= 0 && y >= 0 && x < width && y < height && region[static_cast<std::size_t>(y) * width + x];
  };
  auto isBoundary = [&](int x, int y, int s) {
    const int* n = kDir[(s + 1) % 4];
    return in(x, y) && !in(x - n[0], y - n[1]);
  };
  std::vector<std::uint8_t> visited(region.size(), 0);  // one bit per side
  std::vector<Ring> rings;
  for (int y0 = 0; y0 < height; ++y0)
  {
    for (int x0 = 0; x0 < width; ++x0)
    {
      for (int s0 = 0; s0 < 4; ++s0)
      {
        const std::size_t c0 = static_cast<std::size_t>(y0) * width + x0;
        if (!isBoundary(x0, y0, s0) || (visited[c0] & (1u << s0)))
        {
          continue;
        }
        Ring ring;
        int x = x0;
        int y = y0;
        int s = s0;
        do
        {
          visited[static_cast<std::size_t>(y) * width + x] |= static_cast<std::uint8_t>(1u << s);
          const int* d = kDir[s];
          const int* n = kDir[(s + 1) % 4];
          const Vec2 v(x + kCorner[(s + 1) % 4][0], y + kCorner[(s + 1) % 4][1]);
          if (!in(x + d[0], y + d[1]))
          {
            // Left turn around the same cell; a saddle when the diagonal cell is region too.
            if (in(x + d[0] - n[0], y + d[1] - n[1]))
            {
              ring.push_back(v - kChamfer * Vec2(d[0], d[1]));
              ring.push_back(v + kChamfer * Vec2(n[0], n[1]));
            }
            else
            {
              ring.push_back(v);
            }
            s = (s + 1) % 4;
          }
          else if (!in(x + d[0] - n[0], y + d[1] - n[1]))
          {
            x += d[0];  // straight on along the next cell's same side
            y += d[1];
          }
          else
          {
            ring.push_back(v);  // right turn onto the diagonal cell
            x += d[0] - n[0];
            y += d[1] - n[1];
            s = (s + 3) % 4;
          }
        } while (!(x == x0 && y == y0 && s == s0));
        rings.push_back(std::move(ring));
      }
    }
  }
  return rings;
}

double ringAreaCells(const Ring& ring)
{
  double sum = 0.0;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
  {
    sum += ring[j].x() * ring[i].y() - ring[i].x() * ring[j].y();
  }
  return 0.5 * sum;
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
  if (options.use_seed && !(std::isfinite(options.seed_point.x()) && std::isfinite(options.seed_point.y())))
  {
    throw MapError(source, 0, "seed point must be finite");
  }
}
}  // namespace

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

  const int w = grid.width;
  const int h = grid.height;
  std::vector<char> free(grid.cells.size(), 0);
  for (std::size_t i = 0; i < grid.cells.size(); ++i)
  {
    free[i] = grid.cells[i] >= 0 && grid.cells[i] < options.occupied_threshold;
    info.free_cells += free[i];
  }
  if (info.free_cells == 0)
  {
    throw MapError(source, 0,
                   "no free cell in the " + std::to_string(w) + " x " + std::to_string(h) +
                       " grid (every cell is occupied or unknown): nothing to localize in");
  }
  std::vector<int> labels;
  std::vector<long> sizes;
  info.regions = labelRegions(free, w, h, &labels, &sizes);

  int chosen = 0;
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
  else
  {
    chosen = static_cast<int>(std::max_element(sizes.begin(), sizes.end()) - sizes.begin());
  }
  info.region_cells = sizes[chosen];

  std::vector<char> region(free.size(), 0);
  for (std::size_t i = 0; i < labels.size(); ++i)
  {
    region[i] = labels[i] == chosen;
  }
  std::vector<Ring> contours = traceBoundaries(region, w, h);
  // The outer boundary is the one counter-clockwise ring; every clockwise ring is a hole.
  std::vector<Ring> rings(1);
  double outer_area = 0.0;
  const double min_area_cells = info.min_area_used / (res * res);
  for (Ring& ring : contours)
  {
    const double area = ringAreaCells(ring);
    if (area > outer_area)
    {
      outer_area = area;
      rings[0].swap(ring);
    }
  }
  for (Ring& ring : contours)
  {
    if (ring.empty())
    {
      continue;
    }
    const double area = ringAreaCells(ring);
    if (area >= 0.0)
    {
      continue;  // cannot happen for a 4-connected region; ignore defensively
    }
    ++info.holes_found;
    if (-area < min_area_cells)
    {
      ++info.holes_dropped;
      continue;
    }
    rings.push_back(std::move(ring));
  }
  // Simplify in cell units, where every traced vertex is a multiple of 1/8 cell, so the
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
