#include "fdml_localization/core/adaptive_engine.h"

#include "fdml_localization/core/candidate_refinement.h"

#include <algorithm>
#include <chrono>
#include <numeric>
#include <unordered_map>

namespace fdml_localization
{
namespace core
{
namespace
{
double secondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Union-find over leaf indices.
class DisjointSets
{
public:
  explicit DisjointSets(std::size_t n) : parent_(n) { std::iota(parent_.begin(), parent_.end(), 0); }
  std::size_t find(std::size_t i)
  {
    while (parent_[i] != i)
    {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void unite(std::size_t a, std::size_t b) { parent_[find(a)] = find(b); }

private:
  std::vector<std::size_t> parent_;
};

std::uint64_t cellKey(std::int64_t ix, std::int64_t iy, std::int64_t it)
{
  return (static_cast<std::uint64_t>(ix) << 42) ^ (static_cast<std::uint64_t>(iy) << 21) ^
         static_cast<std::uint64_t>(it);
}

/// Unites every pair of 26-neighbours among @p members (theta periodic).
void uniteNeighbours(const std::vector<LeafBox>& leaves, const std::vector<std::size_t>& members,
                     std::int64_t theta_cells, DisjointSets& sets)
{
  std::unordered_map<std::uint64_t, std::size_t> index;
  index.reserve(members.size() * 2);
  for (const std::size_t i : members)
  {
    index.emplace(cellKey(leaves[i].ix, leaves[i].iy, leaves[i].it), i);
  }
  for (const std::size_t i : members)
  {
    const LeafBox& l = leaves[i];
    for (int dt = -1; dt <= 1; ++dt)
    {
      const std::int64_t t = ((l.it + dt) % theta_cells + theta_cells) % theta_cells;
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dx = -1; dx <= 1; ++dx)
        {
          if (l.ix + dx < 0 || l.iy + dy < 0)
          {
            continue;
          }
          const auto found = index.find(cellKey(l.ix + dx, l.iy + dy, t));
          if (found != index.end())
          {
            sets.unite(i, found->second);
          }
        }
      }
    }
  }
}

/// Mean position and circular-mean heading of the leaves' centres; the leaf nearest to it.
LeafCluster plateauCluster(const std::vector<LeafBox>& leaves, const std::vector<std::size_t>& members)
{
  LeafCluster c;
  double sx = 0.0, sy = 0.0, ss = 0.0, sc = 0.0;
  for (const std::size_t i : members)
  {
    const Pose2 p = leaves[i].box.centre();
    sx += p.x;
    sy += p.y;
    ss += std::sin(p.theta);
    sc += std::cos(p.theta);
  }
  const double n = static_cast<double>(members.size());
  c.centroid = Pose2(sx / n, sy / n, std::atan2(ss, sc));
  double best = kInf;
  for (const std::size_t i : members)
  {
    const Pose2 p = leaves[i].box.centre();
    const double d = (p.position() - c.centroid.position()).squaredNorm() +
                     std::pow(angleDiff(p.theta, c.centroid.theta), 2);
    if (d < best)
    {
      best = d;
      c.representative = i;
    }
  }
  return c;
}
}  // namespace

std::vector<LeafCluster> clusterLeaves(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells)
{
  std::vector<std::size_t> members;
  for (std::size_t i = 0; i < leaves.size(); ++i)
  {
    if (leaves[i].count >= level)
    {
      members.push_back(i);
    }
  }
  DisjointSets components(leaves.size());
  uniteNeighbours(leaves, members, theta_cells, components);
  std::unordered_map<std::size_t, std::vector<std::size_t>> by_root;
  for (const std::size_t i : members)
  {
    by_root[components.find(i)].push_back(i);
  }
  std::vector<LeafCluster> clusters;
  for (auto& entry : by_root)
  {
    const std::vector<std::size_t>& component = entry.second;
    int peak = 0;
    for (const std::size_t i : component)
    {
      peak = std::max(peak, leaves[i].count);
    }
    std::vector<std::size_t> plateau;
    for (const std::size_t i : component)
    {
      if (leaves[i].count == peak)
      {
        plateau.push_back(i);
      }
    }
    DisjointSets plateaus(leaves.size());
    uniteNeighbours(leaves, plateau, theta_cells, plateaus);
    std::unordered_map<std::size_t, std::vector<std::size_t>> parts;
    for (const std::size_t i : plateau)
    {
      parts[plateaus.find(i)].push_back(i);
    }
    for (auto& part : parts)
    {
      LeafCluster c = plateauCluster(leaves, part.second);
      c.size = component.size();
      c.peak_count = peak;
      clusters.push_back(c);
    }
  }
  // Deterministic order: highest peak, then largest component, then position.
  std::sort(clusters.begin(), clusters.end(), [](const LeafCluster& a, const LeafCluster& b) {
    if (a.peak_count != b.peak_count)
    {
      return a.peak_count > b.peak_count;
    }
    if (a.size != b.size)
    {
      return a.size > b.size;
    }
    return a.representative < b.representative;
  });
  return clusters;
}

AdaptiveEngine::AdaptiveEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options)
  : map_(std::move(map)), options_(options)
{
  const Vec2 size = map_->map().bounds().size();
  cell_xy_ = std::max(size.x(), size.y()) / options_.resolution;
  const int nt = options_.theta_resolution > 0 ? options_.theta_resolution : options_.resolution;
  cell_theta_ = kTwoPi / nt;
}

AdaptiveSearchOptions AdaptiveEngine::searchOptions(int min_count) const
{
  AdaptiveSearchOptions o;
  o.cell_xy = cell_xy_;
  o.cell_theta = cell_theta_;
  o.min_count = min_count;
  o.range_tolerance = options_.range_tolerance;
  o.max_boxes = options_.max_boxes;
  o.deadline = options_.deadline;
  o.threads = options_.threads;
  return o;
}

Result AdaptiveEngine::localize(const std::vector<Reading>& readings)
{
  const auto start = std::chrono::steady_clock::now();
  Result result;
  result.engine = Engine::Adaptive;
  result.method = options_.method;
  const int k = static_cast<int>(readings.size());
  result.readings_used = k;
  const std::int64_t theta_cells = std::max<std::int64_t>(1, std::llround(kTwoPi / cell_theta_));

  const bool automatic = options_.method == Method::Robust && options_.min_inliers <= 0;
  int lowest = options_.method == Method::Baseline ? k : options_.min_inliers;
  if (automatic)
  {
    lowest = 3;
  }
  const bool polish = options_.method == Method::Robust;

  RefinementSettings settings;
  settings.agreement_tolerance = options_.agreement_tolerance;
  settings.robust_scale = std::max(options_.agreement_tolerance, 3.0 * cell_xy_);
  settings.noise_sigma = std::max(options_.range_tolerance / std::sqrt(3.0), 1e-4);

  std::vector<Candidate> kept;
  int used_level = lowest;
  // Maximum consensus: search for k' = k first and lower it until a verified candidate appears.
  // With a fixed k' (or the paper's and the baseline's semantics) there is one search.
  for (int level = automatic ? k : lowest; level >= lowest; --level)
  {
    auto stage = std::chrono::steady_clock::now();
    const AdaptiveSearchResult search = adaptiveSearch(*map_, readings, searchOptions(level));
    result.times.preimages += secondsSince(stage);
    result.boxes_per_level = search.boxes_per_level;
    result.truncated = search.truncated;

    stage = std::chrono::steady_clock::now();
    const std::vector<LeafCluster> clusters = clusterLeaves(search.leaves, level, theta_cells);
    result.times.components += secondsSince(stage);

    stage = std::chrono::steady_clock::now();
    std::vector<Candidate> found(clusters.size());
#pragma omp parallel for schedule(dynamic, 1)
    for (long c = 0; c < static_cast<long>(clusters.size()); ++c)
    {
      const LeafCluster& cluster = clusters[c];
      if (polish)
      {
        std::vector<bool> hypothesis(readings.size(), true);
        const std::uint64_t mask = search.leaves[cluster.representative].mask;
        for (std::size_t i = 0; i < readings.size() && i < 64; ++i)
        {
          hypothesis[i] = ((mask >> i) & 1U) != 0;
        }
        found[c] = refineSeed(*map_, cluster.centroid, readings, hypothesis, settings);
      }
      else
      {
        found[c] = verifiedCandidate(*map_, cluster.centroid, readings, options_.agreement_tolerance);
      }
      found[c].support = static_cast<double>(cluster.size);
    }
    (polish ? result.times.polish : result.times.verification) += secondsSince(stage);

    for (Candidate& c : found)
    {
      if (c.inliers >= level)
      {
        kept.push_back(std::move(c));
      }
    }
    used_level = level;
    if (!kept.empty())
    {
      break;
    }
  }
  result.min_inliers_used = used_level;
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance, options_.uniqueness_angle,
                                         options_.max_candidates);
  result.times.total = secondsSince(start);
  return result;
}

}  // namespace core
}  // namespace fdml_localization
