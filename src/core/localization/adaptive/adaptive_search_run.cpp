// The resumable level-by-level box search (AdaptiveSearch).
#include "fdml_localization/core/localization/adaptive/adaptive_search.h"

#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <chrono>

namespace fdml_localization
{
namespace core
{
namespace
{
int levelsFor(std::int64_t cells)
{
  int levels = 0;
  while ((std::int64_t{ 1 } << levels) < cells)
  {
    ++levels;
  }
  return levels;
}

Box2 sweep(const Box2& positions, const Box2& arc, double inflate)
{
  Box2 out;
  out.min = positions.min + arc.min - Vec2(inflate, inflate);
  out.max = positions.max + arc.max + Vec2(inflate, inflate);
  return out;
}

/// Largest arc table kept per level (pairs of boxes); finer theta levels compute arcs directly.
constexpr std::size_t kMaxArcEntries = std::size_t{ 1 } << 20;

enum class Outcome : char
{
  Pruned,
  Kept,
  SetAside
};
}  // namespace

AdaptiveSearch::AdaptiveSearch(const MapRayCaster& map, const BoxOccupancy& occupancy, std::vector<Reading> readings,
                               const AdaptiveSearchOptions& options)
  : map_(map), occupancy_(occupancy), readings_(std::move(readings)), options_(options), start_(Clock::now())
{
  const Box2& bounds = map_.map().bounds();
  root_ =
      options_.region.value_or(PoseBox{ bounds.min.x(), bounds.max.x(), bounds.min.y(), bounds.max.y(), -kPi, kPi });
  root_.t1 = std::min(root_.t1, root_.t0 + kTwoPi);
  // Cell counts; a ratio within rounding of an integer (cell = size / n) gives exactly n cells.
  auto cells = [](double ratio) { return std::max<std::int64_t>(1, std::ceil(ratio * (1.0 - 1e-12))); };
  nx_ = cells((root_.x1 - root_.x0) / options_.cell_xy);
  ny_ = cells((root_.y1 - root_.y0) / options_.cell_xy);
  nt_ = cells((root_.t1 - root_.t0) / options_.cell_theta);
  cell_t_ = (root_.t1 - root_.t0) / static_cast<double>(nt_);
  lx_ = levelsFor(nx_);
  ly_ = levelsFor(ny_);
  lt_ = levelsFor(nt_);
  levels_ = std::max({ lx_, ly_, lt_ });
  set_aside_.resize(levels_ + 1);
  arcs_.resize(levels_ + 1);
  result_.boxes_per_level.assign(levels_ + 1, 0);
  if (options_.floor_count <= 0)
  {
    options_.floor_count = options_.min_count;
  }
}

PoseBox AdaptiveSearch::boxOf(const Node& n, int level) const
{
  auto span = [&](int axis_levels) { return std::int64_t{ 1 } << std::max(axis_levels - level, 0); };
  PoseBox b;
  b.x0 = root_.x0 + n.ix * options_.cell_xy;
  b.x1 = std::min(root_.x1, b.x0 + span(lx_) * options_.cell_xy);
  b.y0 = root_.y0 + n.iy * options_.cell_xy;
  b.y1 = std::min(root_.y1, b.y0 + span(ly_) * options_.cell_xy);
  b.t0 = root_.t0 + n.it * cell_t_;
  b.t1 = std::min(root_.t1, b.t0 + span(lt_) * cell_t_);
  return b;
}

void AdaptiveSearch::prepareArcs(int level)
{
  const std::int64_t span = std::int64_t{ 1 } << std::max(lt_ - level, 0);
  const std::int64_t nodes = (nt_ + span - 1) / span;
  const std::size_t k = readings_.size();
  if (!arcs_[level].empty() || static_cast<std::size_t>(nodes) * k > kMaxArcEntries)
  {
    return;
  }
  arcs_[level].resize(static_cast<std::size_t>(nodes) * k * 2);
  for (std::int64_t t = 0; t < nodes; ++t)
  {
    const double t0 = root_.t0 + t * span * cell_t_;
    const double t1 = std::min(root_.t1, t0 + span * cell_t_);
    for (std::size_t r = 0; r < k; ++r)
    {
      const Reading& reading = readings_[r];
      arcs_[level][(t * k + r) * 2] = hitArcBounds(reading, t0, t1);
      arcs_[level][(t * k + r) * 2 + 1] = rotatedArcBounds(Vec2(reading.offset.x, reading.offset.y), t0, t1);
    }
  }
}

bool AdaptiveSearch::test(Node& n, int level, int min_count) const
{
  const PoseBox b = boxOf(n, level);
  Box2 positions;
  positions.extend(Vec2(b.x0, b.y0));
  positions.extend(Vec2(b.x1, b.y1));
  n.count = 0;
  n.mask = 0;
  if (!occupancy_.mayBeFree(positions) || (options_.positions && !options_.positions->mayBeFree(positions)))
  {
    return false;
  }
  const std::size_t k = readings_.size();
  const std::vector<Box2>& table = arcs_[level];
  const std::size_t row = table.empty() ? 0 : static_cast<std::size_t>(n.it >> std::max(lt_ - level, 0)) * k * 2;
  int count = 0;
  for (std::size_t r = 0; r < k; ++r)
  {
    if (count + static_cast<int>(k - r) < min_count)
    {
      n.count = count + static_cast<int>(k - r);  // upper bound of the full count
      return false;
    }
    const Reading& reading = readings_[r];
    const bool offset = reading.offset.x != 0.0 || reading.offset.y != 0.0;
    // The arcs from the level's table, or computed for this box at the finer theta levels.
    const Box2 hit_arc = table.empty() ? hitArcBounds(reading, b.t0, b.t1) : table[row + 2 * r];
    const Box2 sensor_arc = !table.empty() ? table[row + 2 * r + 1] :
                            offset         ? rotatedArcBounds(Vec2(reading.offset.x, reading.offset.y), b.t0, b.t1) :
                                             Box2();
    // The sensor must be in free space somewhere in the box.
    if (offset && !occupancy_.mayBeFree(sweep(positions, sensor_arc, 0.0)))
    {
      continue;
    }
    bool explained = true;  // a no-return reading is only checked exactly, in verification
    if (std::isfinite(reading.range))
    {
      const Box2 hit = sweep(positions, hit_arc, options_.range_tolerance);
      explained = occupancy_.mayTouchEdge(hit) && map_.grid().anySegmentInBox(hit);
    }
    if (explained)
    {
      ++count;
      if (r < 64)
      {
        n.mask |= std::uint64_t{ 1 } << r;
      }
    }
  }
  n.count = count;
  return count >= min_count;
}

int AdaptiveSearch::consensusBound() const
{
  int bound = options_.floor_count - 1;
  for (const LeafBox& leaf : result_.leaves)
  {
    bound = std::max(bound, leaf.count);
  }
  for (const std::vector<Node>& level : set_aside_)
  {
    for (const Node& n : level)
    {
      bound = std::max(bound, static_cast<int>(n.count));
    }
  }
  return std::min(bound, static_cast<int>(readings_.size()));
}

bool AdaptiveSearch::unresolvedReaches(int count) const
{
  return std::any_of(set_aside_.begin(), set_aside_.end(), [&](const std::vector<Node>& level) {
    return std::any_of(level.begin(), level.end(), [&](const Node& n) { return n.count >= count; });
  });
}

bool AdaptiveSearch::resumeSetAside(int level, int min_count, std::vector<Node>& current)
{
  // Boxes set aside by earlier runs whose upper bound reaches the new k'.
  std::vector<Node>& aside = set_aside_[level];
  auto resumed = std::partition(aside.begin(), aside.end(), [&](const Node& n) { return n.count < min_count; });
  // Within the box budget only: the rest stays aside and the search ends after this level.
  const long room = std::max(0L, options_.max_boxes - result_.boxes_tested - static_cast<long>(current.size()));
  bool cut = false;
  if (aside.end() - resumed > room)
  {
    resumed = aside.end() - room;
    cut = true;
  }
  current.insert(current.end(), resumed, aside.end());
  aside.erase(resumed, aside.end());
  return cut;
}

void AdaptiveSearch::testLevel(int level, int min_count, std::vector<Node>& current, std::vector<Node>& survivors)
{
  const int threads = threadsFor(options_.threads);
  std::vector<Outcome> outcome(current.size(), Outcome::Pruned);
  const long size = static_cast<long>(current.size());
#pragma omp parallel for schedule(dynamic, 64) num_threads(threads) if (size > options_.parallel_threshold)
  for (long i = 0; i < size; ++i)
  {
    if (test(current[i], level, min_count))
    {
      outcome[i] = Outcome::Kept;
    }
    else if (current[i].count >= options_.floor_count)
    {
      outcome[i] = Outcome::SetAside;
    }
  }
  result_.boxes_tested += size;
  survivors.clear();
  for (long i = 0; i < size; ++i)
  {
    if (outcome[i] == Outcome::Kept)
    {
      survivors.push_back(current[i]);
    }
    else if (outcome[i] == Outcome::SetAside)
    {
      set_aside_[level].push_back(current[i]);
    }
  }
  result_.boxes_per_level[level] += static_cast<long>(survivors.size());
}

void AdaptiveSearch::addLeaves(const std::vector<Node>& survivors, int level)
{
  for (const Node& n : survivors)
  {
    LeafBox leaf;
    leaf.box = boxOf(n, level);
    leaf.count = n.count;
    leaf.mask = n.mask;
    leaf.ix = n.ix;
    leaf.iy = n.iy;
    leaf.it = n.it;
    result_.leaves.push_back(leaf);
  }
}

void AdaptiveSearch::split(const std::vector<Node>& survivors, int level, std::vector<Node>& children) const
{
  auto halves = [&](int axis_levels) { return axis_levels > level ? 2 : 1; };
  const int sx = halves(lx_), sy = halves(ly_), st = halves(lt_);
  const std::int32_t cx = static_cast<std::int32_t>(std::int64_t{ 1 } << std::max(lx_ - level - 1, 0));
  const std::int32_t cy = static_cast<std::int32_t>(std::int64_t{ 1 } << std::max(ly_ - level - 1, 0));
  const std::int32_t ct = static_cast<std::int32_t>(std::int64_t{ 1 } << std::max(lt_ - level - 1, 0));
  children.clear();
  children.reserve(survivors.size() * static_cast<std::size_t>(sx * sy * st));
  for (const Node& n : survivors)
  {
    for (int a = 0; a < sx; ++a)
    {
      for (int b = 0; b < sy; ++b)
      {
        for (int c = 0; c < st; ++c)
        {
          const Node child{ n.ix + a * cx, n.iy + b * cy, n.it + c * ct, 0, 0 };
          if (child.ix < nx_ && child.iy < ny_ && child.it < nt_)
          {
            children.push_back(child);
          }
        }
      }
    }
  }
}

const AdaptiveSearchResult& AdaptiveSearch::run(int min_count)
{
  if (finished_)
  {
    return result_;
  }
  std::vector<Node> current;
  if (!started_)
  {
    current.push_back(Node{ 0, 0, 0, 0, 0 });
    started_ = true;
  }
  std::vector<Node> survivors;
  for (int level = 0; level <= levels_; ++level)
  {
    const bool cut = resumeSetAside(level, min_count, current);
    prepareArcs(level);
    testLevel(level, min_count, current, survivors);
    const bool last = level == levels_;
    auto halves = [&](int axis_levels) { return (!last && axis_levels > level) ? 2 : 1; };
    const long children = static_cast<long>(survivors.size()) * halves(lx_) * halves(ly_) * halves(lt_);
    elapsed_ = std::chrono::duration<double>(Clock::now() - start_).count();
    const bool out_of_budget = cut || (!last && (result_.boxes_tested + children > options_.max_boxes ||
                                                 (options_.deadline > 0.0 && elapsed_ > options_.deadline)));
    if (last || out_of_budget)
    {
      // A cut search reports the boxes of the last full level as its leaves and stops for good.
      result_.truncated = out_of_budget && (cut || !survivors.empty());
      finished_ = out_of_budget;
      addLeaves(survivors, level);
      break;
    }
    split(survivors, level, current);
  }
  return result_;
}

}  // namespace core
}  // namespace fdml_localization
