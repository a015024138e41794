// The adaptive engine: the box search (adaptive_search.h), its leaves' plateaus as seeds of the
// shared robust search (seed_search.h), or verified component centres (paper, baseline).
#include "fdml_localization/core/localization/adaptive/adaptive_engine.h"

#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/adaptive/region_fill.h"
#include "fdml_localization/core/localization/certificate.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/region_starts.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/seed_search.h"
#include "fdml_localization/core/util/stopwatch.h"

#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Leaves at the bound (spread over them) whose lattice searchNoReturnRegion() verifies.
constexpr std::size_t kNoReturnScanLeaves = 512;
/// The best lattice poses (one per leaf) refined.
constexpr std::size_t kNoReturnRefined = 4;
/// Leaves of a plateau (spread over it) the final multi-start polishes from.
constexpr std::size_t kRegionStarts = 12;
/// Distinct seeds taken from one plateau.
constexpr std::size_t kSeedsPerPlateau = 3;
/// ... from plateaus of at least this many leaves (smaller ones give one seed).
constexpr std::size_t kLargePlateau = 16;
/// Leaves of a plateau (spread over it) scored for its seeds: a plateau with few finite
/// readings can be large and its exact poses few.
constexpr std::size_t kSampledLeaves = 256;

std::vector<bool> hypothesisOf(const LeafBox& leaf, std::size_t k)
{
  std::vector<bool> hypothesis(k, true);
  for (std::size_t i = 0; i < k && i < 64; ++i)
  {
    hypothesis[i] = ((leaf.mask >> i) & 1U) != 0;
  }
  return hypothesis;
}

/**
 * The plateau's leaves (centres; of at most kSampledLeaves spread over it, plus its centroid)
 * agreeing best with the readings (bestAgreeingPoses()), at most @p max_seeds.
 */
std::vector<Pose2> plateauSeeds(const MapRayCaster& map, const std::vector<LeafBox>& leaves, const LeafCluster& cluster,
                                const std::vector<Reading>& readings, double gate, double separation_xy,
                                double separation_theta, std::size_t max_seeds)
{
  const double reach = leaves[cluster.representative].box.x1 - leaves[cluster.representative].box.x0;
  if (cluster.members.size() < 2)
  {
    return { freeStart(map, cluster.centroid, reach) };
  }
  const std::size_t n = cluster.members.size();
  const std::size_t samples = std::min(n, kSampledLeaves);
  std::vector<Pose2> poses;
  for (std::size_t s = 0; s < samples; ++s)
  {
    poses.push_back(leaves[cluster.members[s * n / samples]].box.centre());
  }
  poses.push_back(cluster.centroid);
  return bestAgreeingPoses(map, poses, readings, gate, separation_xy, separation_theta, max_seeds, poses.size());
}

/// The adaptive engine's seeds, level by level: the best-agreeing distinct leaves of each
/// plateau of leaves whose boxes may explain `level` readings (leafMaxima()).
class LeafSeeds : public SeedSource
{
public:
  LeafSeeds(const MapRayCaster& map, AdaptiveSearch& search, const std::vector<Reading>& readings, double cell_xy,
            double cell_theta, double gate, int threads, StageTimes& times)
    : map_(map)
    , search_(search)
    , readings_(readings)
    , cell_xy_(cell_xy)
    , cell_theta_(cell_theta)
    , gate_(gate)
    , threads_(threads)
    , times_(times)
  {}

  std::vector<SearchSeed> seedsAt(int level) override
  {
    auto stage = std::chrono::steady_clock::now();
    const AdaptiveSearchResult& found = search_.run(level);
    truncated_ = found.truncated;
    times_.preimages += secondsSince(stage);
    stage = std::chrono::steady_clock::now();
    const std::int64_t theta_cells = thetaCells(cell_theta_);
    const std::vector<LeafCluster> plateaus = leafMaxima(found.leaves, level, theta_cells);
    times_.components += secondsSince(stage);
    stage = std::chrono::steady_clock::now();
    std::vector<std::vector<Pose2>> starts(plateaus.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads_) if (plateaus.size() >= 4)
    for (long c = 0; c < static_cast<long>(plateaus.size()); ++c)
    {
      starts[c] = plateauSeeds(map_, found.leaves, plateaus[c], readings_, gate_, 4.0 * cell_xy_, 4.0 * cell_theta_,
                               plateaus[c].members.size() >= kLargePlateau ? kSeedsPerPlateau : 1);
    }
    std::vector<SearchSeed> seeds;
    for (std::size_t c = 0; c < plateaus.size(); ++c)
    {
      const LeafCluster& cluster = plateaus[c];
      const std::size_t n = cluster.members.size();
      for (std::size_t i = 0; i < starts[c].size(); ++i)
      {
        SearchSeed seed;
        seed.start = starts[c][i];
        seed.hypothesis = hypothesisOf(found.leaves[cluster.representative], readings_.size());
        seed.promised = level;
        seed.region = c;
        seed.support = static_cast<double>(cluster.size);
        const auto leafStart = [&](std::size_t m) { return freeStart(map_, found.leaves[m].box.centre(), cell_xy_); };
        if (i == 0)
        {
          // The plateau's retry starts go with its first seed: tried once, not once per seed.
          seed.retry_starts = { leafStart(cluster.representative), leafStart(cluster.members[n / 3]),
                                leafStart(cluster.members[(2 * n) / 3]) };
        }
        const std::size_t spread = std::min(n, kRegionStarts);
        for (std::size_t j = 0; j < spread; ++j)
        {
          seed.region_starts.push_back(leafStart(cluster.members[j * n / spread]));
        }
        if (n > spread)
        {
          auto all = std::make_shared<std::vector<Pose2>>();
          for (std::size_t m : cluster.members)
          {
            all->push_back(found.leaves[m].box.centre());
          }
          seed.region_poses = std::move(all);
        }
        seeds.push_back(std::move(seed));
      }
    }
    times_.verification += secondsSince(stage);
    return seeds;
  }

  bool exhausted() const override
  {
    return truncated_;
  }

private:
  const MapRayCaster& map_;
  AdaptiveSearch& search_;
  const std::vector<Reading>& readings_;
  double cell_xy_;
  double cell_theta_;
  double gate_;
  int threads_;
  StageTimes& times_;
  bool truncated_ = false;
};

}  // namespace

Result AdaptiveEngine::localize(const std::vector<Reading>& readings)
{
  const auto start = std::chrono::steady_clock::now();
  Result result;
  result.engine = Engine::Adaptive;
  result.method = options_.method;
  const int k = static_cast<int>(readings.size());
  result.readings_used = k;
  const bool robust = options_.method == Method::Robust;
  const int lowest = options_.method == Method::Baseline ? k : (options_.min_inliers > 0 ? options_.min_inliers : 3);
  AdaptiveSearchOptions search_options = searchOptions(lowest);
  search_options.floor_count = lowest;
  AdaptiveSearch search(*map_, *occupancy_, readings, search_options);
  if (robust)
  {
    localizeRobust(search, readings, result);
  }
  else
  {
    localizeFixed(search, readings, lowest, result);
  }
  result.boxes_per_level = search.result().boxes_per_level;
  result.truncated = search.result().truncated;
  const std::int64_t theta_cells = thetaCells(cell_theta_);
  certifyAdaptive(*map_, readings, options_.range_tolerance, search, theta_cells, result);
  last_leaves_ = search.result().leaves;
  result.times.total = secondsSince(start);
  return result;
}

void AdaptiveEngine::localizeFixed(AdaptiveSearch& search, const std::vector<Reading>& readings, int level,
                                   Result& result)
{
  const std::int64_t theta_cells = thetaCells(cell_theta_);
  const int threads = threadsFor(options_.threads);
  auto stage = std::chrono::steady_clock::now();
  const AdaptiveSearchResult& found = search.run(level);
  result.times.preimages += secondsSince(stage);
  stage = std::chrono::steady_clock::now();
  const std::vector<LeafCluster> clusters = clusterLeaves(found.leaves, level, theta_cells);
  result.times.components += secondsSince(stage);
  stage = std::chrono::steady_clock::now();
  std::vector<Candidate> candidates(clusters.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (clusters.size() >= 4)
  for (long c = 0; c < static_cast<long>(clusters.size()); ++c)
  {
    candidates[c] = verifiedCandidate(*map_, clusters[c].centroid, readings, options_.agreement_tolerance);
    candidates[c].support = static_cast<double>(clusters[c].size);
  }
  result.times.verification += secondsSince(stage);
  std::vector<Candidate> kept;
  for (Candidate& c : candidates)
  {
    if (c.inliers >= level)
    {
      kept.push_back(std::move(c));
    }
  }
  result.min_inliers_used = level;
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance, options_.uniqueness_angle,
                                         options_.max_candidates);
}

void AdaptiveEngine::localizeRobust(AdaptiveSearch& search, const std::vector<Reading>& readings, Result& result)
{
  const int threads = threadsFor(options_.threads);
  const SeedScale scale{ cell_xy_, cell_theta_ };
  // A plateau's leaves are ranked with the shared search's loose agreement band.
  LeafSeeds seeds(*map_, search, readings, cell_xy_, cell_theta_, seedGate(readings, options_, scale), threads,
                  result.times);
  SeedSearchOutcome found = robustSearch(seeds, *map_, readings, options_, scale, result.times);
  result.min_inliers_used = found.min_inliers_used;
  result.candidates = std::move(found.candidates);
  searchNoReturnRegion(search, readings, result);
  const auto stage = std::chrono::steady_clock::now();
  const std::int64_t theta_cells = thetaCells(cell_theta_);
  const RefinementSettings settings = latticeRefinement(options_, cell_xy_, cell_theta_);
  fillUncoveredRegions(*map_, search.result().leaves, theta_cells, readings, options_, settings, result);
  settleInNearBasins(*map_, readings, options_, settings, result.candidates);
  result.times.polish += secondsSince(stage);
}

void AdaptiveEngine::searchNoReturnRegion(const AdaptiveSearch& search, const std::vector<Reading>& readings,
                                          Result& result) const
{
  // No candidate at all is possible: where every reading is a no-return, the seeds' plateau is
  // the whole free space and the few poses clear of walls in every sensor's range can escape
  // its sampled leaves (4 no-returns with a 2.3 m range in the warehouse).
  const int best_net = result.candidates.empty() ? -1 : netConsensus(result.candidates.front());
  const int bound = search.consensusBound();
  const bool no_returns =
      std::any_of(readings.begin(), readings.end(), [](const Reading& r) { return !std::isfinite(r.range); });
  if (!no_returns || best_net >= bound)
  {
    return;
  }
  std::vector<const LeafBox*> at_bound;
  for (const LeafBox& leaf : search.result().leaves)
  {
    if (leaf.count >= bound)
    {
      at_bound.push_back(&leaf);
    }
  }
  std::vector<Candidate> lattice_best =
      leafLatticeBests(*map_, at_bound, kNoReturnScanLeaves, readings, options_.agreement_tolerance);
  const std::size_t refined = std::min(kNoReturnRefined, lattice_best.size());
  std::partial_sort(lattice_best.begin(), lattice_best.begin() + static_cast<std::ptrdiff_t>(refined),
                    lattice_best.end(), betterCandidate);
  const RefinementSettings settings = latticeRefinement(options_, cell_xy_, cell_theta_);
  Candidate found;
  int found_net = best_net;
  for (std::size_t i = 0; i < refined; ++i)
  {
    const Candidate& start = lattice_best[i];
    Candidate c = refineSeed(*map_, start.pose, readings, start.inlier_mask, settings);
    Candidate& better = betterCandidate(c, start) ? c : lattice_best[i];
    if (netConsensus(better) > found_net)
    {
      found = better;
      found_net = netConsensus(better);
    }
  }
  if (found_net > best_net)
  {
    ensureCovariance(*map_, readings, settings.noise_sigma, found);
    settleAlongContinua(*map_, readings, settings, found);
    // An automatic k' is the largest consensus found.
    result.min_inliers_used = options_.min_inliers > 0 ? result.min_inliers_used : found_net;
    result.candidates.insert(result.candidates.begin(), std::move(found));
    result.candidates = rankAndDeduplicate(std::move(result.candidates), options_.uniqueness_distance,
                                           options_.uniqueness_angle, options_.max_candidates);
  }
}

AdaptiveEngine::AdaptiveEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options)
  : map_(std::move(map)), options_(options)
{
  const Vec2 size = searchBounds(*map_, options_).size();
  cell_xy_ = std::max(size.x(), size.y()) / options_.resolution;
  const int nt = options_.theta_resolution > 0 ? options_.theta_resolution : options_.resolution;
  cell_theta_ = kTwoPi / nt;
  occupancy_ = std::make_shared<const BoxOccupancy>(*map_, cell_xy_, kOccupancyCells);
  if (options_.search_region)
  {
    region_occupancy_ = std::make_shared<const BoxOccupancy>(*options_.search_region, cell_xy_, kOccupancyCells);
  }
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
  if (region_occupancy_)
  {
    const Box2 b = searchBounds(*map_, options_);
    o.region = PoseBox{ b.min.x(), b.max.x(), b.min.y(), b.max.y(), -kPi, kPi };
    o.positions = region_occupancy_.get();
  }
  return o;
}

}  // namespace core
}  // namespace fdml_localization
