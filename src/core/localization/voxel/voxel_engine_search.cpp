// The voxel engine's candidate stages: component centres (paper, baseline) and the robust
// search (maximal hypotheses and count peaks as seeds, polish, automatic or fixed k').
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/hypothesis_seeds.h"
#include "fdml_localization/core/util/stopwatch.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Seeds retried from other voxels of their plateau when no seed reaches a level ...
constexpr std::size_t kRetriedSeeds = 32;
/// ... of which this many first get a local lattice search around their centroid.
constexpr std::size_t kLocallySearchedSeeds = 8;

/// What the robust search needs to refine a seed.
struct SearchContext
{
  const MapRayCaster& map;
  const GridSpec& spec;
  const std::vector<Reading>& readings;
  RefinementSettings settings;
  double loose_gate = 0.0;  ///< agreement band of the rough count at a seed's centroid [m]
  int threads = 1;
};

/// The seeds of the robust search and what became of them, in the order they were found.
struct SeedPool
{
  std::vector<VoxelCluster> plateaus;  ///< peak_count = readings the seed's voxels explain
  std::vector<std::vector<bool>> hypotheses;
  std::vector<Candidate> candidates;
  std::vector<int> rough;  ///< readings agreeing within the loose gate at the centroid
  std::vector<char> refined;
  std::vector<char> retried;

  void add(VoxelCluster plateau, std::vector<bool> hypothesis)
  {
    plateaus.push_back(std::move(plateau));
    hypotheses.push_back(std::move(hypothesis));
  }

  /// The most inliers of any candidate so far.
  int best() const
  {
    return std::accumulate(candidates.begin(), candidates.end(), 0,
                           [](int m, const Candidate& c) { return std::max(m, c.inliers); });
  }

  /// The largest net consensus (inliers - contradicted readings) of any candidate so far.
  int bestNet() const
  {
    return std::accumulate(candidates.begin(), candidates.end(), 0,
                           [](int m, const Candidate& c) { return std::max(m, netConsensus(c)); });
  }

  /// Verifies the seeds added since the last call at their centroids.
  void evaluateNew(const SearchContext& ctx)
  {
    const long first = static_cast<long>(candidates.size());
    const long n = static_cast<long>(plateaus.size());
    candidates.resize(n);
    rough.resize(n, 0);
    refined.resize(n, 0);
    retried.resize(n, 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx.threads) if (n - first >= 4)
    for (long c = first; c < n; ++c)
    {
      const Pose2& centroid = plateaus[c].centroid;
      candidates[c] = verifiedCandidate(ctx.map, centroid, ctx.readings, ctx.settings.agreement_tolerance);
      rough[c] = evaluatePose(ctx.map, centroid, ctx.readings, ctx.loose_gate).inliers;
    }
  }

  /// Refines, once, every seed that could reach @p level: as many readings in its plateau and
  /// at least level - 2 of them roughly agreeing at its centroid.
  void refineFor(int level, const SearchContext& ctx)
  {
    const RefinementSettings with = levelSettings(level, ctx);
    const long n = static_cast<long>(plateaus.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx.threads) if (n >= 4)
    for (long c = 0; c < n; ++c)
    {
      if (!refined[c] && plateaus[c].peak_count >= level && rough[c] >= level - 2)
      {
        refined[c] = 1;
        keepBetter(c, refineSeed(ctx.map, plateaus[c].centroid, ctx.readings, hypotheses[c], with));
      }
    }
  }

  /**
   * @brief Second chances for the seeds that promise @p level but fell short: the optimum may
   *        lie across an occlusion edge from the centroid, where no descent reaches it, or far
   *        from it on a large plateau. The most promising (most readings, then most rough
   *        agreement) get a local lattice search and restarts from other plateau voxels; a
   *        fixed number, so the result does not depend on thread timing.
   */
  void retryFor(int level, const SearchContext& ctx)
  {
    std::vector<long> order;
    for (long c = 0; c < static_cast<long>(plateaus.size()); ++c)
    {
      if (!retried[c] && plateaus[c].peak_count >= level && netConsensus(candidates[c]) < level)
      {
        order.push_back(c);
      }
    }
    std::stable_sort(order.begin(), order.end(), [&](long a, long b) {
      return plateaus[a].peak_count != plateaus[b].peak_count ? plateaus[a].peak_count > plateaus[b].peak_count :
                                                                rough[a] > rough[b];
    });
    order.resize(std::min(order.size(), kRetriedSeeds));
    const RefinementSettings with = levelSettings(level, ctx);
    RefinementSettings search = with;
    search.local_search_cells = 2;
    search.local_search_step = 0.5 * ctx.spec.cell;
    search.local_search_angle_step = 0.5 * ctx.spec.thetaStep();
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx.threads) if (order.size() >= 2)
    for (std::size_t j = 0; j < order.size(); ++j)
    {
      const long c = order[j];
      retried[c] = 1;
      const VoxelCluster& plateau = plateaus[c];
      if (j < kLocallySearchedSeeds)
      {
        keepBetter(c, refineSeed(ctx.map, plateau.centroid, ctx.readings, hypotheses[c], search));
      }
      const std::size_t n = plateau.voxels.size();
      for (std::size_t v : { plateau.representative, plateau.voxels[n / 3], plateau.voxels[(2 * n) / 3] })
      {
        if (netConsensus(candidates[c]) < level)
        {
          keepBetter(c, refineSeed(ctx.map, ctx.spec.centre(v), ctx.readings, hypotheses[c], with));
        }
      }
    }
  }

private:
  static RefinementSettings levelSettings(int level, const SearchContext& ctx)
  {
    RefinementSettings with = ctx.settings;
    with.escape_min_inliers = std::max(3, level - 1);
    with.target_inliers = level;
    return with;
  }

  void keepBetter(long c, Candidate candidate)
  {
    if (betterCandidate(candidate, candidates[c]))
    {
      candidates[c] = std::move(candidate);
    }
  }
};
}  // namespace

void VoxelEngine::localizeComponentCentres(const std::vector<Reading>& readings, int min_inliers, Result& result)
{
  result.min_inliers_used = min_inliers;
  auto stage = std::chrono::steady_clock::now();
  const std::vector<VoxelCluster> clusters = connectedComponents(spec_, count_, min_inliers);
  result.times.components = secondsSince(stage);

  stage = std::chrono::steady_clock::now();
  std::vector<Candidate> candidates(clusters.size());
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads()) if (clusters.size() >= 8)
  for (long c = 0; c < static_cast<long>(clusters.size()); ++c)
  {
    candidates[c] = verifiedCandidate(*map_, clusters[c].centroid, readings, options_.agreement_tolerance);
    candidates[c].support = static_cast<double>(clusters[c].voxels.size());
  }
  std::vector<Candidate> kept;
  for (Candidate& c : candidates)
  {
    if (c.inliers >= min_inliers)
    {
      kept.push_back(std::move(c));
    }
  }
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance, options_.uniqueness_angle,
                                         options_.max_candidates);
  result.times.verification = secondsSince(stage);
}

void VoxelEngine::localizeRobust(const std::vector<Reading>& readings, Result& result)
{
  const int k = static_cast<int>(readings.size());
  const bool automatic = options_.min_inliers <= 0;
  const int lowest = automatic ? 3 : options_.min_inliers;

  std::vector<double> finite;
  for (const Reading& r : readings)
  {
    if (std::isfinite(r.range))
    {
      finite.push_back(r.range);
    }
  }
  double typical_range = 1.0;
  if (!finite.empty())
  {
    std::nth_element(finite.begin(), finite.begin() + finite.size() / 2, finite.end());
    typical_range = finite[finite.size() / 2];
  }
  SearchContext ctx{ *map_, spec_, readings, RefinementSettings(), 0.0, threads() };
  ctx.settings.agreement_tolerance = options_.agreement_tolerance;
  ctx.settings.robust_scale =
      std::max(options_.agreement_tolerance, 0.5 * spec_.cell + 0.5 * spec_.thetaStep() * typical_range);
  ctx.settings.noise_sigma = std::max(options_.range_tolerance / std::sqrt(3.0), 1e-4);
  ctx.settings.seed_position_error = 1.5 * spec_.cell;
  ctx.settings.seed_angle_error = spec_.thetaStep();
  ctx.loose_gate = 3.0 * ctx.settings.robust_scale;

  // Seeds, level by level: every locally maximal set of readings of the raw preimages
  // (hypothesis_seeds.h) and, because the raw test can miss the truth's voxel next to a
  // discontinuity of h, the count peaks of the dilated preimages.
  auto stage = std::chrono::steady_clock::now();
  const std::vector<std::vector<std::size_t>> buckets = voxelsByCount(count_, lowest, k);
  const std::vector<std::vector<std::size_t>> raw_buckets = voxelsByCount(raw_count_, lowest, k);
  result.times.components += secondsSince(stage);

  SeedPool pool;
  int used_level = lowest;
  bool reached = false;
  for (int level = k; level >= lowest && !reached; --level)
  {
    stage = std::chrono::steady_clock::now();
    for (HypothesisSeed& h : maximalHypotheses(spec_, raw_sets_, raw_count_, level, raw_buckets[level], threads()))
    {
      pool.add(std::move(h.plateau), std::move(h.hypothesis));
    }
    for (VoxelCluster& c : regionalMaxima(spec_, count_, level, buckets[level]))
    {
      std::vector<bool> hypothesis = membership(c.representative, sets_);
      pool.add(std::move(c), std::move(hypothesis));
    }
    result.times.components += secondsSince(stage);
    stage = std::chrono::steady_clock::now();
    pool.evaluateNew(ctx);
    result.times.verification += secondsSince(stage);
    stage = std::chrono::steady_clock::now();
    pool.refineFor(level, ctx);
    result.times.polish += secondsSince(stage);

    if (automatic)
    {
      // Maximum consensus: the first level some seed reaches, net of the readings its pose
      // contradicts (a pose where a reading passes through a wall must explain one more).
      reached = pool.bestNet() >= level;
      used_level = reached ? level : used_level;
    }
    else if (level > lowest)
    {
      // Fixed k': once max_candidates distinct poses explain at least `level` readings net, the
      // lower levels' seeds (which promise fewer) cannot enter the ranked list.
      std::vector<Candidate> strong;
      std::copy_if(pool.candidates.begin(), pool.candidates.end(), std::back_inserter(strong),
                   [&](const Candidate& c) { return netConsensus(c) >= level; });
      const std::vector<Candidate> ranked = rankAndDeduplicate(std::move(strong), options_.uniqueness_distance,
                                                               options_.uniqueness_angle, options_.max_candidates);
      reached = static_cast<int>(ranked.size()) >= options_.max_candidates;
    }
  }
  // Second chances, one level above what was reached (automatic: a larger consensus may have
  // been missed) or at k' when nothing reached it.
  stage = std::chrono::steady_clock::now();
  if (automatic)
  {
    for (int target = reached ? used_level + 1 : lowest; target <= k; target = used_level + 1)
    {
      pool.retryFor(target, ctx);
      if (pool.bestNet() < target)
      {
        break;
      }
      used_level = pool.bestNet();
    }
  }
  else if (pool.best() < lowest)
  {
    pool.retryFor(lowest, ctx);
  }
  result.times.polish += secondsSince(stage);
  result.min_inliers_used = automatic ? used_level : options_.min_inliers;

  std::vector<Candidate> kept;
  for (std::size_t c = 0; c < pool.candidates.size(); ++c)
  {
    if (pool.candidates[c].inliers >= result.min_inliers_used)
    {
      // The seed voxel rides in support until the duplicates are gone.
      pool.candidates[c].support = static_cast<double>(pool.plateaus[c].representative);
      kept.push_back(std::move(pool.candidates[c]));
    }
  }
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance, options_.uniqueness_angle,
                                         options_.max_candidates);
  stage = std::chrono::steady_clock::now();
  std::vector<std::size_t> voxels;
  for (const Candidate& c : result.candidates)
  {
    voxels.push_back(static_cast<std::size_t>(c.support));
  }
  const std::vector<std::size_t> sizes = componentSizes(spec_, count_, result.min_inliers_used, voxels);
  for (std::size_t i = 0; i < sizes.size(); ++i)
  {
    result.candidates[i].support = static_cast<double>(sizes[i]);
  }
  result.times.components += secondsSince(stage);
}

}  // namespace core
}  // namespace fdml_localization
