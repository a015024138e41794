#include "fdml_localization/core/adaptive_search.h"

#include <omp.h>

#include <algorithm>
#include <chrono>

namespace fdml_localization
{
namespace core
{
namespace
{
/// A node of the implicit octree over the leaf index space, at some level.
struct Node
{
  std::int64_t ix, iy, it;  ///< index of the node's first leaf cell along each axis
  int count;
  std::uint64_t mask;
};

int levelsFor(std::int64_t cells)
{
  int levels = 0;
  while ((std::int64_t{ 1 } << levels) < cells)
  {
    ++levels;
  }
  return levels;
}

/// True when a box that meets no map edge lies outside free space (test its centre).
bool outsideFreeSpace(const MapRayCaster& map, const Box2& box)
{
  return !map.grid().anySegmentInBox(box) && !map.isFree(0.5 * (box.min + box.max));
}

Box2 sweep(const Box2& positions, const Vec2& v, double t0, double t1, double inflate)
{
  const Box2 arc = rotatedArcBounds(v, t0, t1);
  Box2 out;
  out.min = positions.min + arc.min - Vec2(inflate, inflate);
  out.max = positions.max + arc.max + Vec2(inflate, inflate);
  return out;
}
}  // namespace

Box2 rotatedArcBounds(const Vec2& v, double t0, double t1)
{
  Box2 box;
  const double r = v.norm();
  if (r == 0.0)
  {
    box.extend(Vec2::Zero());
    return box;
  }
  const double phi = std::atan2(v.y(), v.x());
  const double a0 = t0 + phi;
  const double a1 = t1 + phi;
  box.extend(Vec2(r * std::cos(a0), r * std::sin(a0)));
  box.extend(Vec2(r * std::cos(a1), r * std::sin(a1)));
  // Axis extremes at multiples of pi/2 inside [a0, a1].
  for (double k = std::ceil(a0 / (0.5 * kPi)); k * 0.5 * kPi <= a1; k += 1.0)
  {
    const double a = k * 0.5 * kPi;
    box.extend(Vec2(r * std::cos(a), r * std::sin(a)));
  }
  return box;
}

bool readingMayExplain(const MapRayCaster& map, const Reading& reading, const PoseBox& box, double range_tolerance)
{
  Box2 positions;
  positions.extend(Vec2(box.x0, box.y0));
  positions.extend(Vec2(box.x1, box.y1));
  const Pose2& g = reading.offset;
  // The sensor must be in free space somewhere in the box (for a sensor at the base origin the
  // caller's robot-position test already says so).
  if ((g.x != 0.0 || g.y != 0.0) && outsideFreeSpace(map, sweep(positions, Vec2(g.x, g.y), box.t0, box.t1, 0.0)))
  {
    return false;
  }
  if (!std::isfinite(reading.range))
  {
    return true;  // a no-return reading is only checked exactly, in verification
  }
  const Vec2 v(g.x + reading.range * std::cos(g.theta), g.y + reading.range * std::sin(g.theta));
  return map.grid().anySegmentInBox(sweep(positions, v, box.t0, box.t1, range_tolerance));
}

AdaptiveSearchResult adaptiveSearch(const MapRayCaster& map, const std::vector<Reading>& readings,
                                    const AdaptiveSearchOptions& options)
{
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  AdaptiveSearchResult result;
  const Box2& bounds = map.map().bounds();
  const std::int64_t nx = std::max<std::int64_t>(1, std::ceil(bounds.size().x() / options.cell_xy));
  const std::int64_t ny = std::max<std::int64_t>(1, std::ceil(bounds.size().y() / options.cell_xy));
  const std::int64_t nt = std::max<std::int64_t>(1, std::ceil(kTwoPi / options.cell_theta));
  const double cell_t = kTwoPi / static_cast<double>(nt);
  const int lx = levelsFor(nx), ly = levelsFor(ny), lt = levelsFor(nt);
  const int levels = std::max({ lx, ly, lt });
  if (options.threads > 0)
  {
    omp_set_num_threads(options.threads);
  }

  auto span = [&](int axis_levels, int level) { return std::int64_t{ 1 } << std::max(axis_levels - level, 0); };
  auto box_of = [&](const Node& n, int level) {
    PoseBox b;
    b.x0 = bounds.min.x() + n.ix * options.cell_xy;
    b.x1 = std::min(bounds.max.x(), b.x0 + span(lx, level) * options.cell_xy);
    b.y0 = bounds.min.y() + n.iy * options.cell_xy;
    b.y1 = std::min(bounds.max.y(), b.y0 + span(ly, level) * options.cell_xy);
    b.t0 = -kPi + n.it * cell_t;
    b.t1 = std::min(kPi, b.t0 + span(lt, level) * cell_t);
    return b;
  };

  std::vector<Node> current{ Node{ 0, 0, 0, 0, 0 } };
  std::vector<Node> kept;
  for (int level = 0; level <= levels; ++level)
  {
    kept.assign(current.size(), Node{});
    std::vector<char> keep(current.size(), 0);
#pragma omp parallel for schedule(dynamic, 64)
    for (std::size_t i = 0; i < current.size(); ++i)
    {
      Node n = current[i];
      const PoseBox b = box_of(n, level);
      Box2 positions;
      positions.extend(Vec2(b.x0, b.y0));
      positions.extend(Vec2(b.x1, b.y1));
      if (outsideFreeSpace(map, positions))
      {
        continue;
      }
      int count = 0;
      std::uint64_t mask = 0;
      for (std::size_t r = 0; r < readings.size(); ++r)
      {
        // Stop early once the box can no longer reach min_count.
        if (count + static_cast<int>(readings.size() - r) < options.min_count)
        {
          break;
        }
        if (readingMayExplain(map, readings[r], b, options.range_tolerance))
        {
          ++count;
          if (r < 64)
          {
            mask |= std::uint64_t{ 1 } << r;
          }
        }
      }
      if (count >= options.min_count)
      {
        n.count = count;
        n.mask = mask;
        kept[i] = n;
        keep[i] = 1;
      }
    }
    result.boxes_tested += static_cast<long>(current.size());
    std::vector<Node> survivors;
    for (std::size_t i = 0; i < current.size(); ++i)
    {
      if (keep[i])
      {
        survivors.push_back(kept[i]);
      }
    }
    result.boxes_per_level.push_back(static_cast<long>(survivors.size()));

    const bool last = level == levels;
    // Children of the survivors: split every axis that is not yet at leaf size.
    const std::int64_t cx = span(lx, level + 1), cy = span(ly, level + 1), ct = span(lt, level + 1);
    const int sx = (!last && lx > level) ? 2 : 1, sy = (!last && ly > level) ? 2 : 1, st = (!last && lt > level) ? 2 : 1;
    const long children = static_cast<long>(survivors.size()) * sx * sy * st;
    const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
    const bool out_of_budget = result.boxes_tested + children > options.max_boxes ||
                               (options.deadline > 0.0 && elapsed > options.deadline);
    if (last || out_of_budget || survivors.empty())
    {
      result.truncated = !last && out_of_budget && !survivors.empty();
      for (const Node& n : survivors)
      {
        LeafBox leaf;
        leaf.box = box_of(n, level);
        leaf.count = n.count;
        leaf.mask = n.mask;
        leaf.ix = n.ix;
        leaf.iy = n.iy;
        leaf.it = n.it;
        result.leaves.push_back(leaf);
      }
      break;
    }
    current.clear();
    current.reserve(static_cast<std::size_t>(children));
    for (const Node& n : survivors)
    {
      for (int a = 0; a < sx; ++a)
      {
        for (int b = 0; b < sy; ++b)
        {
          for (int c = 0; c < st; ++c)
          {
            const Node child{ n.ix + a * cx, n.iy + b * cy, n.it + c * ct, 0, 0 };
            if (child.ix < nx && child.iy < ny && child.it < nt)
            {
              current.push_back(child);
            }
          }
        }
      }
    }
  }
  return result;
}

}  // namespace core
}  // namespace fdml_localization
