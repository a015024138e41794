// The voxel engine's candidate stages: component centres (paper, baseline) and the robust
// search's seeds (maximal hypotheses and count peaks) for the shared robust search (seed_search.h).
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "fdml_localization/core/localization/voxel/box_screen.h"
#include "fdml_localization/core/localization/voxel/count_buckets.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/seed_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/adaptive/region_fill.h"
#include "fdml_localization/core/localization/hypothesis_seeds.h"
#include "fdml_localization/core/localization/region_starts.h"
#include "fdml_localization/core/util/stopwatch.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <memory>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Voxels of a plateau (spread over it) the final multi-start polishes from.
constexpr std::size_t kRegionStarts = 12;
/// Voxels of a conservative regional maximum (spread over it) scored for its seeds ...
constexpr std::size_t kSampledVoxels = 512;
/// ... which gives three distinct seeds from this many voxels on (smaller ones one).
constexpr std::size_t kLargePlateau = 16;

/// The voxel engine's seeds, level by level: every locally maximal set of readings of the
/// seeding's sample preimages (hypothesis_seeds.h) and, because that test can miss the truth's
/// voxel next to a discontinuity of h, the count peaks of their dilation.
class VoxelSeeds : public SeedSource
{
public:
  VoxelSeeds(const VoxelEngine& engine, const BoxScreen& screen, const BlockMaxima& blocks, double gate, int lowest,
             int k, StageTimes& times)
    : engine_(engine)
    , map_(screen.map)
    , readings_(screen.readings)
    , screen_(screen)
    , gate_(gate)
    , times_(times)
    , conservative_(engine.grid(), engine.lastCount(), blocks)
    , buckets_(engine.lastSeedCount(), engine.grid().nx, lowest, k)
    , raw_buckets_(engine.lastRawCount(), engine.grid().nx, lowest, k)
  {}

  std::vector<SearchSeed> seedsAt(int level) override
  {
    const auto stage = std::chrono::steady_clock::now();
    const GridSpec& spec = engine_.grid();
    std::vector<SearchSeed> seeds;
    for (HypothesisSeed& h : maximalHypotheses(spec, engine_.lastRawPreimages(), engine_.lastRawCount(), level,
                                               raw_buckets_.at(level), engine_.threads()))
    {
      seeds.push_back(seedOf(h.plateau, std::move(h.hypothesis)));
    }
    for (VoxelCluster& c : regionalMaxima(spec, engine_.lastSeedCount(), level, buckets_.at(level)))
    {
      seeds.push_back(seedOf(c, engine_.membership(c.representative, engine_.lastSeedPreimages())));
    }
    addConservativeSeeds(level, seeds);
    times_.components += secondsSince(stage);
    return seeds;
  }

private:
  /// The sample tests can miss the truth's voxel next to a discontinuity of h; the conservative
  /// count field never does: each of its regional maxima the box test lets reach the level
  /// (ScreenedCount) also gives the voxels (of some spread over it) agreeing best with the
  /// readings.
  void addConservativeSeeds(int level, std::vector<SearchSeed>& seeds)
  {
    const GridSpec& spec = engine_.grid();
    const std::vector<VoxelCluster> maxima = conservative_.maximaAt(level, screen_);
    std::vector<std::vector<Pose2>> starts(maxima.size());
#pragma omp parallel for schedule(dynamic, 4) num_threads(engine_.threads()) if (maxima.size() >= 8)
    for (long m = 0; m < static_cast<long>(maxima.size()); ++m)
    {
      const VoxelCluster& c = maxima[m];
      const std::size_t n = c.voxels.size();
      const std::size_t samples = std::min(n, kSampledVoxels);
      std::vector<Pose2> poses;
      for (std::size_t s = 0; s < samples; ++s)
      {
        poses.push_back(spec.centre(c.voxels[s * n / samples]));
      }
      poses.push_back(c.centroid);
      starts[m] = bestAgreeingPoses(map_, poses, readings_, gate_, 2.0 * spec.cell, 2.0 * spec.thetaStep(),
                                    n >= kLargePlateau ? 3 : 1, poses.size());
    }
    for (std::size_t m = 0; m < maxima.size(); ++m)
    {
      const std::vector<bool> hypothesis = engine_.membership(maxima[m].representative, engine_.lastPreimages());
      for (std::size_t j = 0; j < starts[m].size(); ++j)
      {
        // The region's retry starts are its first seed's: tried once, not once per seed.
        seeds.push_back(seedOf(maxima[m], hypothesis, j == 0));
        seeds.back().start = starts[m][j];
      }
    }
  }

  /// A seed of @p plateau: its free start, retry starts (@p with_retries) and region starts.
  SearchSeed seedOf(const VoxelCluster& plateau, std::vector<bool> hypothesis, bool with_retries = true) const
  {
    SearchSeed seed;
    const GridSpec& spec = engine_.grid();
    seed.start = freeStart(map_, plateau.centroid, spec.cell);
    seed.hypothesis = std::move(hypothesis);
    seed.promised = plateau.peak_count;
    seed.region = plateau.representative;
    const std::size_t n = plateau.voxels.size();
    if (with_retries)
    {
      for (std::size_t v : { plateau.representative, plateau.voxels[n / 3], plateau.voxels[(2 * n) / 3] })
      {
        seed.retry_starts.push_back(freeStart(map_, spec.centre(v), spec.cell));
      }
    }
    // The final multi-start's poses, spread over the plateau: it may hold several optima.
    const std::size_t spread = std::min(n, kRegionStarts);
    for (std::size_t j = 0; j < spread; ++j)
    {
      seed.region_starts.push_back(freeStart(map_, spec.centre(plateau.voxels[j * n / spread]), spec.cell));
    }
    if (n > spread)
    {
      auto all = std::make_shared<std::vector<Pose2>>();
      all->reserve(n);
      std::transform(plateau.voxels.begin(), plateau.voxels.end(), std::back_inserter(*all),
                     [&](std::size_t v) { return spec.centre(v); });
      seed.region_poses = std::move(all);
    }
    return seed;
  }

  const VoxelEngine& engine_;
  const MapRayCaster& map_;
  const std::vector<Reading>& readings_;
  BoxScreen screen_;
  double gate_;
  StageTimes& times_;
  ScreenedCount conservative_;
  CountBuckets buckets_;
  CountBuckets raw_buckets_;
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
  const int lowest = options_.min_inliers > 0 ? options_.min_inliers : 3;
  const BoxScreen screen{ *map_, readings, std::max(options_.range_tolerance, options_.agreement_tolerance),
                          threads() };
  // The conservative count's top blocks (the screens skip those below their level).
  const BlockMaxima blocks(spec_, count_);
  VoxelSeeds seeds(*this, screen, blocks, seedGate(readings, options_, SeedScale{ spec_.cell, spec_.thetaStep() }),
                   lowest, k, result.times);
  SeedSearchOutcome found =
      robustSearch(seeds, *map_, readings, options_, SeedScale{ spec_.cell, spec_.thetaStep() }, result.times);
  result.min_inliers_used = found.min_inliers_used;
  result.candidates = std::move(found.candidates);
  // Support: the size of the component of each candidate's seed voxel at k'.
  const auto stage = std::chrono::steady_clock::now();
  const std::vector<std::size_t> sizes = componentSizes(spec_, count_, result.min_inliers_used, found.regions);
  for (std::size_t i = 0; i < sizes.size(); ++i)
  {
    result.candidates[i].support = static_cast<double>(sizes[i]);
  }
  result.times.components += secondsSince(stage);
  // The places the seeds missed: the voxels reaching the best candidate's consensus (conservative
  // count) searched as the adaptive engine's leaves are.
  const auto fill = std::chrono::steady_clock::now();
  if (!result.candidates.empty())
  {
    const int target = netConsensus(result.candidates.front());
    // The box test bounds a voxel's consensus tighter than the count's distance bounds (and it
    // stops early where the target is out of reach): only the voxels passing become leaves.
    const std::vector<LeafBox> leaves = reachingLeaves(
        spec_, count_, target, blocks, BoxScreen{ *map_, readings, options_.range_tolerance, threads() });
    const RefinementSettings settings = latticeRefinement(options_, spec_.cell, spec_.thetaStep());
    fillUncoveredRegions(*map_, leaves, spec_.nt, readings, options_, settings, result);
    settleInNearBasins(*map_, readings, options_, settings, result.candidates);
  }
  result.times.polish += secondsSince(fill);
}

}  // namespace core
}  // namespace fdml_localization
