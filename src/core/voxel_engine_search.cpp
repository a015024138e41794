// The voxel engine's candidate stages: component centres (paper, baseline) and the robust
// search (count peaks as seeds, polish, automatic or fixed k').
#include "fdml_localization/core/voxel_engine.h"

#include "fdml_localization/core/candidate_refinement.h"
#include "fdml_localization/core/components.h"
#include "fdml_localization/core/stopwatch.h"

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

/// Seeds of a level (in processing order) that may be retried from other voxels of their plateau.
constexpr long kRetriedSeeds = 32;
/// ... of which this many first get a local lattice search around their centroid.
constexpr long kLocallySearchedSeeds = 8;
}  // namespace

void VoxelEngine::localizeComponentCentres(const std::vector<Reading>& readings, int min_inliers,
                                           Result& result)
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
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance,
                                         options_.uniqueness_angle, options_.max_candidates);
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
  RefinementSettings settings;
  settings.agreement_tolerance = options_.agreement_tolerance;
  settings.robust_scale = std::max(options_.agreement_tolerance,
                                   0.5 * spec_.cell + 0.5 * spec_.thetaStep() * typical_range);
  settings.noise_sigma = std::max(options_.range_tolerance / std::sqrt(3.0), 1e-4);
  settings.seed_position_error = 1.5 * spec_.cell;
  settings.seed_angle_error = spec_.thetaStep();
  // Seeds where fewer than (level - 2) readings agree even this loosely are not polished.
  const double loose_gate = 3.0 * settings.robust_scale;

  // Seeds come from the count peaks of the dilated preimages and, because the dilation can
  // merge an obstacle hit's surface into the truth's peak, also from those of the raw ones.
  auto stage = std::chrono::steady_clock::now();
  const std::vector<std::vector<std::size_t>> buckets = voxelsByCount(count_, lowest, k);
  const std::vector<std::vector<std::size_t>> raw_buckets = voxelsByCount(raw_count_, lowest, k);
  result.times.components += secondsSince(stage);

  std::vector<Seed> seeds;
  int used_level = lowest;
  for (int level = k; level >= lowest; --level)
  {
    stage = std::chrono::steady_clock::now();
    std::vector<VoxelCluster> maxima = regionalMaxima(spec_, count_, level, buckets[level]);
    const std::size_t dilated_maxima = maxima.size();
    for (VoxelCluster& c : regionalMaxima(spec_, raw_count_, level, raw_buckets[level]))
    {
      maxima.push_back(std::move(c));
    }
    result.times.components += secondsSince(stage);

    const std::size_t first = seeds.size();
    seeds.resize(first + maxima.size());
    std::vector<std::vector<bool>> hypotheses(maxima.size());
    std::vector<char> plausible(maxima.size(), 0);
    stage = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads()) if (maxima.size() >= 4)
    for (long c = 0; c < static_cast<long>(maxima.size()); ++c)
    {
      Seed& seed = seeds[first + c];
      seed.voxel = maxima[c].representative;
      hypotheses[c] = membership(seed.voxel, static_cast<std::size_t>(c) < dilated_maxima ? sets_ : raw_sets_);
      seed.candidate = verifiedCandidate(*map_, maxima[c].centroid, readings, options_.agreement_tolerance);
      plausible[c] = evaluatePose(*map_, maxima[c].centroid, readings, loose_gate).inliers >= level - 2;
    }
    result.times.verification += secondsSince(stage);

    stage = std::chrono::steady_clock::now();
    RefinementSettings level_settings = settings;
    level_settings.escape_min_inliers = std::max(3, level - 1);
    level_settings.target_inliers = level;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads()) if (maxima.size() >= 4)
    for (long c = 0; c < static_cast<long>(maxima.size()); ++c)
    {
      if (plausible[c])
      {
        seeds[first + c].candidate = refineSeed(*map_, maxima[c].centroid, readings, hypotheses[c], level_settings);
      }
    }
    // No seed so far explains as many readings as this level's count promises: one of this
    // level's seeds may sit behind an occlusion edge. Retry the first of them from other voxels
    // of their plateaus (a fixed number, so the result does not depend on thread timing).
    const int best_so_far = std::accumulate(seeds.begin(), seeds.end(), 0, [](int m, const Seed& s) {
      return std::max(m, s.candidate.inliers);
    });
    if (best_so_far < level)
    {
      const long retried = std::min<long>(static_cast<long>(maxima.size()), kRetriedSeeds);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads()) if (retried >= 4)
      for (long c = 0; c < retried; ++c)
      {
        Seed& seed = seeds[first + c];
        const VoxelCluster& cluster = maxima[c];
        const std::size_t n = cluster.voxels.size();
        if (seed.candidate.inliers < level && c < kLocallySearchedSeeds)
        {
          // First the seed itself again, now with a local lattice search.
          RefinementSettings search = level_settings;
          search.local_search_cells = 2;
          search.local_search_step = 0.5 * spec_.cell;
          search.local_search_angle_step = 0.5 * spec_.thetaStep();
          Candidate retry = refineSeed(*map_, cluster.centroid, readings, hypotheses[c], search);
          if (betterCandidate(retry, seed.candidate))
          {
            seed.candidate = std::move(retry);
          }
        }
        for (std::size_t v : { cluster.representative, cluster.voxels[n / 3], cluster.voxels[(2 * n) / 3] })
        {
          if (seed.candidate.inliers >= level)
          {
            break;
          }
          Candidate retry = refineSeed(*map_, spec_.centre(v), readings, hypotheses[c], level_settings);
          if (betterCandidate(retry, seed.candidate))
          {
            seed.candidate = std::move(retry);
          }
        }
      }
    }
    result.times.polish += secondsSince(stage);

    if (automatic)
    {
      const bool found = std::any_of(seeds.begin(), seeds.end(),
                                     [&](const Seed& s) { return s.candidate.inliers >= level; });
      if (found)
      {
        used_level = level;
        break;
      }
    }
    else if (level > lowest)
    {
      // Fixed k': once max_candidates distinct poses explain at least `level` readings, the
      // lower levels' seeds (which promise fewer) cannot enter the ranked list.
      std::vector<Candidate> strong;
      for (const Seed& s : seeds)
      {
        if (s.candidate.inliers >= level)
        {
          strong.push_back(s.candidate);
        }
      }
      const std::vector<Candidate> ranked = rankAndDeduplicate(
          std::move(strong), options_.uniqueness_distance, options_.uniqueness_angle, options_.max_candidates);
      if (static_cast<int>(ranked.size()) >= options_.max_candidates)
      {
        break;
      }
    }
  }
  result.min_inliers_used = automatic ? used_level : options_.min_inliers;

  std::vector<Candidate> kept;
  for (Seed& seed : seeds)
  {
    if (seed.candidate.inliers >= result.min_inliers_used)
    {
      // The seed voxel rides in support until the duplicates are gone.
      seed.candidate.support = static_cast<double>(seed.voxel);
      kept.push_back(std::move(seed.candidate));
    }
  }
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance,
                                         options_.uniqueness_angle, options_.max_candidates);
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
