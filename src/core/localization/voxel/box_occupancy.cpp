#include "fdml_localization/core/localization/voxel/box_occupancy.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Summed-area table (nx+1) x (ny+1) of a 0/1 cell array nx x ny (row-major in y).
std::vector<std::int32_t> summedArea(const std::vector<std::uint8_t>& cells, int nx, int ny)
{
  std::vector<std::int32_t> sum(static_cast<std::size_t>(nx + 1) * (ny + 1), 0);
  for (int y = 0; y < ny; ++y)
  {
    std::int32_t row = 0;
    for (int x = 0; x < nx; ++x)
    {
      row += cells[static_cast<std::size_t>(y) * nx + x];
      sum[static_cast<std::size_t>(y + 1) * (nx + 1) + x + 1] =
          sum[static_cast<std::size_t>(y) * (nx + 1) + x + 1] + row;
    }
  }
  return sum;
}
}  // namespace

BoxOccupancy::BoxOccupancy(const MapRayCaster& map, double cell_size, int max_cells_per_side)
{
  bounds_ = map.map().bounds();
  if (bounds_.empty())
  {
    return;
  }
  const Vec2 size = bounds_.size();
  const double longest = std::max({ size.x(), size.y(), 1e-9 });
  cell_ = std::max(cell_size, longest / std::max(1, max_cells_per_side));
  inv_cell_ = 1.0 / cell_;
  nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / cell_)));
  const std::vector<std::uint8_t> edge = edgeCells(map, longest);
  const std::vector<std::uint8_t> free_or_edge = freeOrEdgeCells(map, edge);
  edge_sum_ = summedArea(edge, nx_, ny_);
  free_sum_ = summedArea(free_or_edge, nx_, ny_);
}

std::vector<std::uint8_t> BoxOccupancy::edgeCells(const MapRayCaster& map, double longest) const
{
  std::vector<std::uint8_t> edge(static_cast<std::size_t>(nx_) * ny_, 0);
  // Mark every cell an edge may touch: per column strip, the edge's y range there, widened by
  // a margin that absorbs rounding.
  const double margin = 1e-6 * longest + 1e-9;
  auto clampX = [&](double x) { return cellIndex(x - bounds_.min.x(), nx_); };
  auto clampY = [&](double y) { return cellIndex(y - bounds_.min.y(), ny_); };
  for (const Segment& s : map.map().edges())
  {
    const double xa = std::min(s.a.x(), s.b.x()) - margin, xb = std::max(s.a.x(), s.b.x()) + margin;
    for (int cx = clampX(xa); cx <= clampX(xb); ++cx)
    {
      const double sx0 = std::max(xa, bounds_.min.x() + cx * cell_);
      const double sx1 = std::min(xb, bounds_.min.x() + (cx + 1) * cell_);
      double ya = std::min(s.a.y(), s.b.y()), yb = std::max(s.a.y(), s.b.y());
      const double dx = s.b.x() - s.a.x();
      if (std::abs(dx) > 1e-12)
      {
        const double y0 = s.a.y() + (s.b.y() - s.a.y()) * (sx0 - s.a.x()) / dx;
        const double y1 = s.a.y() + (s.b.y() - s.a.y()) * (sx1 - s.a.x()) / dx;
        ya = std::max(ya, std::min(y0, y1));
        yb = std::min(yb, std::max(y0, y1));
      }
      for (int cy = clampY(ya - margin); cy <= clampY(yb + margin); ++cy)
      {
        edge[static_cast<std::size_t>(cy) * nx_ + cx] = 1;
      }
    }
  }
  return edge;
}

std::vector<std::uint8_t> BoxOccupancy::freeOrEdgeCells(const MapRayCaster& map,
                                                        const std::vector<std::uint8_t>& edge) const
{
  // Regions of edge-free cells: one point-in-polygon test each.
  std::vector<std::uint8_t> free_or_edge(edge);
  std::vector<std::uint8_t> seen(edge);
  std::vector<std::size_t> stack;
  std::vector<std::size_t> region;
  for (std::size_t start = 0; start < edge.size(); ++start)
  {
    if (seen[start])
    {
      continue;
    }
    region.clear();
    stack.assign(1, start);
    seen[start] = 1;
    while (!stack.empty())
    {
      const std::size_t c = stack.back();
      stack.pop_back();
      region.push_back(c);
      const int x = static_cast<int>(c % nx_), y = static_cast<int>(c / nx_);
      const std::size_t next[4] = { x > 0 ? c - 1 : c, x + 1 < nx_ ? c + 1 : c, y > 0 ? c - nx_ : c,
                                    y + 1 < ny_ ? c + nx_ : c };
      for (const std::size_t n : next)
      {
        if (!seen[n])
        {
          seen[n] = 1;
          stack.push_back(n);
        }
      }
    }
    const int x = static_cast<int>(start % nx_), y = static_cast<int>(start / nx_);
    const Vec2 centre = bounds_.min + Vec2((x + 0.5) * cell_, (y + 0.5) * cell_);
    if (map.isFree(centre))
    {
      for (const std::size_t c : region)
      {
        free_or_edge[c] = 1;
      }
    }
  }
  return free_or_edge;
}

std::int64_t BoxOccupancy::count(const std::vector<std::int32_t>& table, const Box2& box) const
{
  if (table.empty() || box.empty() || box.max.x() < bounds_.min.x() || box.max.y() < bounds_.min.y() ||
      box.min.x() > bounds_.max.x() || box.min.y() > bounds_.max.y())
  {
    return 0;
  }
  // Edges within a rounding margin of a cell border are marked on both sides, so the cells
  // holding the box's corners suffice.
  const int x0 = cellIndex(box.min.x() - bounds_.min.x(), nx_);
  const int x1 = cellIndex(box.max.x() - bounds_.min.x(), nx_);
  const int y0 = cellIndex(box.min.y() - bounds_.min.y(), ny_);
  const int y1 = cellIndex(box.max.y() - bounds_.min.y(), ny_);
  const std::size_t w = static_cast<std::size_t>(nx_) + 1;
  return static_cast<std::int64_t>(table[(y1 + 1) * w + x1 + 1]) - table[(y1 + 1) * w + x0] - table[y0 * w + x1 + 1] +
         table[y0 * w + x0];
}

int BoxOccupancy::cellIndex(double offset, int cells) const
{
  // Clamped in floating point first (offsets may be far outside, or NaN), then truncated (>= 0).
  const double c = offset * inv_cell_;
  if (!(c > 0.0))
  {
    return 0;
  }
  return c < cells - 1 ? static_cast<int>(c) : cells - 1;
}

bool BoxOccupancy::mayTouchEdge(const Box2& box) const
{
  return count(edge_sum_, box) > 0;
}

bool BoxOccupancy::mayBeFree(const Box2& box) const
{
  return count(free_sum_, box) > 0;
}

}  // namespace core
}  // namespace fdml_localization
