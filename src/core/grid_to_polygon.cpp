#include "fdml_localization/core/grid_to_polygon.h"

#include "fdml_localization/core/map_io.h"
#include "fdml_localization/core/ring_simplify.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <unordered_map>

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
  std::vector<int> queue;
  for (std::size_t start = 0; start < free.size(); ++start)
  {
    if (!free[start] || (*labels)[start] >= 0)
    {
      continue;
    }
    const int label = static_cast<int>(sizes->size());
    long count = 0;
    queue.assign(1, static_cast<int>(start));
    (*labels)[start] = label;
    while (!queue.empty())
    {
      const int idx = queue.back();
      queue.pop_back();
      ++count;
      const int x = idx % width;
      const int y = idx / width;
      const int neighbours[4][2] = {{x - 1, y}, {x + 1, y}, {x, y - 1}, {x, y + 1}};
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
          queue.push_back(nidx);
        }
      }
    }
    sizes->push_back(count);
  }
  return static_cast<int>(sizes->size());
}

/**
 * Marching squares over the region mask, padded by one non-region cell on every side. Nodes
 * are cell centres; contour points are midpoints between a region node and a non-region node.
 * Each square emits segments with the region on their left, pairing each exit crossing with
 * the entry crossing before it in counter-clockwise order, so at a saddle the two region
 * cells stay apart (the region is 4-connected, the walls 8-connected). Returns rings in local
 * cell units: cell (ix, iy) spans [ix, ix + 1] x [iy, iy + 1].
 */
std::vector<Ring> traceContours(const std::vector<char>& region, int width, int height)
{
  const int pw = width + 2;
  const int ph = height + 2;
  auto inside = [&](int i, int j) {
    const int x = i - 1;
    const int y = j - 1;
    return x >= 0 && y >= 0 && x < width && y < height && region[static_cast<std::size_t>(y) * width + x];
  };
  // Crossing keys: 2 * node + 0 for the edge to the node's right, + 1 for the edge above it.
  auto hKey = [&](int i, int j) { return 2 * (static_cast<std::int64_t>(j) * pw + i); };
  auto vKey = [&](int i, int j) { return 2 * (static_cast<std::int64_t>(j) * pw + i) + 1; };
  std::unordered_map<std::int64_t, std::int64_t> next;
  for (int j = 0; j + 1 < ph; ++j)
  {
    for (int i = 0; i + 1 < pw; ++i)
    {
      const bool c[4] = {inside(i, j), inside(i + 1, j), inside(i + 1, j + 1), inside(i, j + 1)};
      if (c[0] == c[1] && c[1] == c[2] && c[2] == c[3])
      {
        continue;
      }
      const std::int64_t keys[4] = {hKey(i, j), vKey(i + 1, j), hKey(i, j + 1), vKey(i, j)};
      for (int k = 0; k < 4; ++k)
      {
        if (!(c[k] && !c[(k + 1) % 4]))
        {
          continue;  // not an exit crossing
        }
        for (int back = 1; back < 4; ++back)
        {
          const int m = (k + 4 - back) % 4;
          if (!c[m] && c[(m + 1) % 4])
          {
            next[keys[k]] = keys[m];
            break;
          }
        }
      }
    }
  }
  auto pointOf = [&](std::int64_t key) {
    const std::int64_t node = key / 2;
    const double i = static_cast<double>(node % pw);
    const double j = static_cast<double>(node / pw);
    // Node (i, j) is the centre of cell (i - 1, j - 1), at (i - 0.5, j - 0.5) in cell units.
    return (key % 2 == 0) ? Vec2(i, j - 0.5) : Vec2(i - 0.5, j);
  };
  std::vector<Ring> rings;
  std::unordered_map<std::int64_t, bool> used;
  used.reserve(next.size());
  for (const auto& entry : next)
  {
    if (used.count(entry.first))
    {
      continue;
    }
    Ring ring;
    std::int64_t key = entry.first;
    while (!used.count(key))
    {
      used[key] = true;
      ring.push_back(pointOf(key));
      const auto it = next.find(key);
      if (it == next.end())
      {
        break;
      }
      key = it->second;
    }
    rings.push_back(std::move(ring));
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
    throw MapError(source, 0, "occupied_threshold must be in [1, 100] (got " +
                                  std::to_string(options.occupied_threshold) + ")");
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
    throw MapError(source, 0, "no free cell in the " + std::to_string(w) + " x " + std::to_string(h) +
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
      throw MapError(source, 0, "seed point " + formatPoint(options.seed_point) + " lies in a " +
                                    (grid.at(ix, iy) < 0 ? "unknown" : "occupied") + " cell (" + std::to_string(ix) +
                                    ", " + std::to_string(iy) + ") of value " + std::to_string(grid.at(ix, iy)));
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
  std::vector<Ring> contours = traceContours(region, w, h);
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
  // Into metres in the grid's frame (simplify there: yaw does not change distances).
  for (Ring& ring : rings)
  {
    info.vertices_traced += static_cast<long>(ring.size());
    for (Vec2& p : ring)
    {
      p *= res;
    }
  }
  SimplifyStats stats;
  std::vector<Ring> simple = simplifyRings(rings, info.tolerance_used, &stats);
  info.rings_tightened = stats.rings_tightened;
  for (Ring& ring : simple)
  {
    info.vertices_kept += static_cast<long>(ring.size());
    for (Vec2& p : ring)
    {
      p = grid.toMap(p);
    }
  }
  if (report != nullptr)
  {
    *report = info;
  }
  return PolygonMap::fromRings(std::move(simple), source);
}

PolygonMap loadMapFile(const std::string& path, const GridConversionOptions& options, GridConversionReport* report)
{
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".poly")
  {
    return loadPolyFile(path);
  }
  if (ext == ".yaml" || ext == ".yml")
  {
    return gridToPolygon(loadOccupancyGridYaml(path), options, path, report);
  }
  throw MapError(path, 0, "unknown map file type '" + ext +
                              "' (allowed: .poly polygon files, .yaml/.yml map_server occupancy grids)");
}

}  // namespace core
}  // namespace fdml_localization
