#include "fdml_localization/core/geometry/ray_caster.h"

#include <algorithm>
#include <atomic>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kMaxCellsPerAxis = 4096;

/// A thread's last MapRayCaster::isFree() verdict (map 0: none).
struct FreeMemo
{
  std::uint64_t map = 0;
  double x = 0.0;
  double y = 0.0;
  bool free = false;
};

/// A new MapRayCaster's id (from 1), unique in the process.
std::uint64_t nextMapId()
{
  static std::atomic<std::uint64_t> next{ 1 };
  return next.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

SegmentGrid::SegmentGrid(std::vector<Segment> segments, double cell_size) : segments_(std::move(segments))
{
  for (const Segment& s : segments_)
  {
    bounds_.extend(s.a);
    bounds_.extend(s.b);
  }
  if (segments_.empty())
  {
    return;
  }
  // Inflate a little so that every segment lies strictly inside the grid.
  const double pad = 1e-9 * std::max(1.0, bounds_.size().maxCoeff());
  bounds_.min -= Vec2(pad, pad);
  bounds_.max += Vec2(pad, pad);
  const Vec2 size = bounds_.size();
  if (cell_size <= 0.0)
  {
    // About two segments' worth of cells per segment: short cell lists, few empty cells to cross.
    const double cells = 2.0 * static_cast<double>(segments_.size());
    cell_size = std::sqrt(size.x() * size.y() / cells);
  }
  cell_size = std::max({ cell_size, size.x() / kMaxCellsPerAxis, size.y() / kMaxCellsPerAxis });
  cell_ = cell_size;
  nx_ = std::max(1, static_cast<int>(std::ceil(size.x() / cell_)));
  ny_ = std::max(1, static_cast<int>(std::ceil(size.y() / cell_)));

  buildCells();
  buildCentreParity();
}

template <typename Fn>
void SegmentGrid::forEachCellTouching(const Segment& s, Fn&& fn) const
{
  const double margin = 1e-9 * std::max(1.0, cell_);
  const int x0 = cellX(std::min(s.a.x(), s.b.x()) - margin);
  const int x1 = cellX(std::max(s.a.x(), s.b.x()) + margin);
  const int y0 = cellY(std::min(s.a.y(), s.b.y()) - margin);
  const int y1 = cellY(std::max(s.a.y(), s.b.y()) + margin);
  for (int cy = y0; cy <= y1; ++cy)
  {
    for (int cx = x0; cx <= x1; ++cx)
    {
      Box2 cell;
      cell.min = bounds_.min + Vec2(cx * cell_ - margin, cy * cell_ - margin);
      cell.max = bounds_.min + Vec2((cx + 1) * cell_ + margin, (cy + 1) * cell_ + margin);
      if (segmentIntersectsBox(s, cell))
      {
        fn(static_cast<std::size_t>(cy) * nx_ + cx);
      }
    }
  }
}

void SegmentGrid::buildCells()
{
  // Two passes (count, then fill) into compressed rows. A cell takes a segment that touches
  // the cell inflated by a small margin, so that hits on cell borders are found from both sides.
  std::vector<std::uint32_t> counts(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
  for (const Segment& s : segments_)
  {
    forEachCellTouching(s, [&](std::size_t cell) { ++counts[cell + 1]; });
  }
  cell_start_.assign(counts.size(), 0);
  for (std::size_t i = 1; i < counts.size(); ++i)
  {
    cell_start_[i] = cell_start_[i - 1] + counts[i];
  }
  cell_items_.resize(cell_start_.back());
  std::vector<std::uint32_t> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (std::size_t i = 0; i < segments_.size(); ++i)
  {
    forEachCellTouching(segments_[i], [&](std::size_t cell) { cell_items_[fill[cell]++] = static_cast<int>(i); });
  }
}

RayHit SegmentGrid::castBruteForce(const Vec2& origin, const Vec2& dir, double max_range) const
{
  RayHit best;
  for (std::size_t i = 0; i < segments_.size(); ++i)
  {
    const double t = raySegmentDistance(origin, dir, segments_[i]);
    if (t < best.distance)
    {
      best.distance = t;
      best.segment = static_cast<int>(i);
    }
  }
  if (best.distance > max_range)
  {
    return RayHit();
  }
  return best;
}

bool SegmentGrid::clipToBounds(const Vec2& origin, const Vec2& dir, double* t_enter, double* t_exit) const
{
  // Slab test against the grid's box.
  for (int axis = 0; axis < 2; ++axis)
  {
    if (dir[axis] == 0.0)
    {
      if (origin[axis] < bounds_.min[axis] || origin[axis] > bounds_.max[axis])
      {
        return false;
      }
      continue;
    }
    double ta = (bounds_.min[axis] - origin[axis]) / dir[axis];
    double tb = (bounds_.max[axis] - origin[axis]) / dir[axis];
    if (ta > tb)
    {
      std::swap(ta, tb);
    }
    *t_enter = std::max(*t_enter, ta);
    *t_exit = std::min(*t_exit, tb);
  }
  return *t_enter <= *t_exit;
}

void SegmentGrid::castInCell(std::size_t cell, const Vec2& origin, const Vec2& dir, RayHit* best) const
{
  for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k)
  {
    const int i = cell_items_[k];
    const double t = raySegmentDistance(origin, dir, segments_[i]);
    if (t < best->distance || (t == best->distance && i < best->segment))
    {
      best->distance = t;
      best->segment = i;
    }
  }
}

double SegmentGrid::nextBorder(const Vec2& origin, const Vec2& dir, int axis, int c, int step) const
{
  if (dir[axis] == 0.0)
  {
    return kInf;
  }
  const double border = bounds_.min[axis] + (step > 0 ? c + 1 : c) * cell_;
  return (border - origin[axis]) / dir[axis];
}

RayHit SegmentGrid::cast(const Vec2& origin, const Vec2& dir, double max_range) const
{
  RayHit best;
  if (segments_.empty() || !(max_range >= 0.0))
  {
    return best;
  }
  double t_enter = 0.0;
  double t_exit = max_range;
  // From inside the grid's box the walk starts at the origin and needs no exit: every segment lies
  // inside the box, so the cells beyond it (if any) hold no hit nearer than one inside it.
  if (!bounds_.contains(origin) && !clipToBounds(origin, dir, &t_enter, &t_exit))
  {
    return best;
  }
  const Vec2 start = origin + t_enter * dir;
  int cx = cellX(start.x());
  int cy = cellY(start.y());
  const int step_x = dir.x() > 0.0 ? 1 : -1;
  const int step_y = dir.y() > 0.0 ? 1 : -1;
  double t_max_x = nextBorder(origin, dir, 0, cx, step_x);
  double t_max_y = nextBorder(origin, dir, 1, cy, step_y);
  const double dt_x = dir.x() == 0.0 ? kInf : cell_ / std::abs(dir.x());
  const double dt_y = dir.y() == 0.0 ? kInf : cell_ / std::abs(dir.y());

  while (true)
  {
    const std::size_t cell = static_cast<std::size_t>(cy) * nx_ + cx;
    if (cell_start_[cell] != cell_start_[cell + 1])
    {
      castInCell(cell, origin, dir, &best);
    }
    const double t_cell_exit = std::min(t_max_x, t_max_y);
    // Any hit in a later cell lies beyond this cell's exit. The tiny slack keeps ties (a hit
    // exactly on the border) resolved the same way as the brute-force loop.
    if (best.distance < t_cell_exit - 1e-12 * std::max(1.0, t_cell_exit) || t_cell_exit > t_exit)
    {
      break;
    }
    if (t_max_x < t_max_y)
    {
      cx += step_x;
      t_max_x += dt_x;
    }
    else
    {
      cy += step_y;
      t_max_y += dt_y;
    }
    if (cx < 0 || cx >= nx_ || cy < 0 || cy >= ny_)
    {
      break;
    }
  }
  if (best.distance > max_range)
  {
    return RayHit();
  }
  return best;
}

void SegmentGrid::forEachSegmentInBox(const Box2& box, const std::function<bool(int)>& fn) const
{
  if (segments_.empty() || !box.intersects(bounds_))
  {
    return;
  }
  const int x0 = cellX(box.min.x());
  const int x1 = cellX(box.max.x());
  const int y0 = cellY(box.min.y());
  const int y1 = cellY(box.max.y());
  // A segment listed in several cells is reported once: only from the first cell (in scan
  // order) of the queried range that lists it.
  std::vector<int> seen;
  for (int cy = y0; cy <= y1; ++cy)
  {
    for (int cx = x0; cx <= x1; ++cx)
    {
      const std::size_t cell = static_cast<std::size_t>(cy) * nx_ + cx;
      for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k)
      {
        const int i = cell_items_[k];
        if (std::find(seen.begin(), seen.end(), i) != seen.end() || !segmentIntersectsBox(segments_[i], box))
        {
          continue;
        }
        seen.push_back(i);
        if (!fn(i))
        {
          return;
        }
      }
    }
  }
}

bool SegmentGrid::anySegmentInBox(const Box2& box) const
{
  if (segments_.empty() || !box.intersects(bounds_))
  {
    return false;
  }
  const int x0 = cellX(box.min.x());
  const int x1 = cellX(box.max.x());
  const int y0 = cellY(box.min.y());
  const int y1 = cellY(box.max.y());
  for (int cy = y0; cy <= y1; ++cy)
  {
    for (int cx = x0; cx <= x1; ++cx)
    {
      const std::size_t cell = static_cast<std::size_t>(cy) * nx_ + cx;
      for (std::uint32_t k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k)
      {
        if (segmentIntersectsBox(segments_[cell_items_[k]], box))
        {
          return true;
        }
      }
    }
  }
  return false;
}

int SegmentGrid::crossingsToRight(const Vec2& p) const
{
  if (segments_.empty() || p.y() < bounds_.min.y() || p.y() > bounds_.max.y() || p.x() > bounds_.max.x())
  {
    return 0;
  }
  const int cy = cellY(p.y());
  std::vector<int> candidates;
  for (int cx = cellX(p.x()); cx < nx_; ++cx)
  {
    const std::size_t cell = static_cast<std::size_t>(cy) * nx_ + cx;
    candidates.insert(candidates.end(), cell_items_.begin() + cell_start_[cell],
                      cell_items_.begin() + cell_start_[cell + 1]);
  }
  std::sort(candidates.begin(), candidates.end());
  candidates.erase(std::unique(candidates.begin(), candidates.end()), candidates.end());
  int crossings = 0;
  for (const int i : candidates)
  {
    crossings += crossesRightOf(p, segments_[i].a, segments_[i].b) ? 1 : 0;
  }
  return crossings;
}

MapRayCaster::MapRayCaster(PolygonMap map, double cell_size)
  : map_(std::move(map)), grid_(map_.edges(), cell_size), id_(nextMapId())
{}

double MapRayCaster::range(const Pose2& sensor, double max_range) const
{
  return grid_.cast(sensor.position(), sensor.heading(), max_range).distance;
}

bool MapRayCaster::isFree(const Vec2& p) const
{
  if (map_.empty() || !map_.bounds().contains(p))
  {
    return false;
  }
  // The thread's last verdict, for this map's contents and exactly this point.
  thread_local FreeMemo memo;
  if (memo.map != id_ || memo.x != p.x() || memo.y != p.y())
  {
    memo = FreeMemo{ id_, p.x(), p.y(), grid_.oddCrossingsToRight(p) };
  }
  return memo.free;
}

}  // namespace core
}  // namespace fdml_localization
