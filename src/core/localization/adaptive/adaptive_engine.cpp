// AdaptiveEngine::localize: the box search, then the voxel engine's seed, polish and ranking
// stages on the leaves (regional maxima per k', retries, maximum consensus).
#include "fdml_localization/core/localization/adaptive/adaptive_engine.h"

#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/util/stopwatch.h"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Seeds retried from other leaves of their plateau when no seed reaches the level.
constexpr long kRetriedSeeds = 32;
/// ... of which this many also get a local lattice search around the seed.
constexpr long kLocallySearchedSeeds = 8;
/// Distinct seeds taken from one plateau.
constexpr std::size_t kSeedsPerPlateau = 3;
/// ... from plateaus of at least this many leaves (smaller ones give one seed).
constexpr std::size_t kLargePlateau = 16;

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
 * The plateau leaves (of at most kSampledLeaves spread over it, plus its centroid) whose centres
 * agree best with the readings (fewest readings off by more than @p gate, then smallest squared
 * residuals), at most @p max_seeds of them and pairwise apart by more than @p separation_xy [m]
 * or @p separation_theta [rad]. A large plateau (few finite readings constrain it) can hold
 * several distinct optima and its centroid can lie far from all of them.
 */
std::vector<Pose2> plateauSeeds(const MapRayCaster& map, const std::vector<LeafBox>& leaves, const LeafCluster& cluster,
                                const std::vector<Reading>& readings, double gate, double separation_xy,
                                double separation_theta, std::size_t max_seeds)
{
  constexpr std::size_t kSampledLeaves = 32;
  if (cluster.members.size() < 2)
  {
    return { cluster.centroid };
  }
  std::vector<std::pair<double, Pose2>> scored;
  const std::size_t n = cluster.members.size();
  const std::size_t samples = std::min(n, kSampledLeaves);
  for (std::size_t s = 0; s <= samples; ++s)
  {
    const Pose2 pose = s == samples ? cluster.centroid : leaves[cluster.members[s * n / samples]].box.centre();
    const PoseEvaluation e = evaluatePose(map, pose, readings, gate);
    double score = static_cast<double>(readings.size() - e.inliers) * gate * gate;
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      if (e.inlier_mask[i] && std::isfinite(e.residuals[i]))
      {
        score += e.residuals[i] * e.residuals[i];
      }
    }
    scored.emplace_back(score, pose);
  }
  std::stable_sort(
      scored.begin(), scored.end(),
      [](const std::pair<double, Pose2>& a, const std::pair<double, Pose2>& b) { return a.first < b.first; });
  std::vector<Pose2> seeds;
  for (const auto& entry : scored)
  {
    const Pose2& p = entry.second;
    const bool distinct = std::all_of(seeds.begin(), seeds.end(), [&](const Pose2& q) {
      return (p.position() - q.position()).norm() > separation_xy ||
             std::abs(angleDiff(p.theta, q.theta)) > separation_theta;
    });
    if (distinct)
    {
      seeds.push_back(p);
    }
    if (seeds.size() >= max_seeds)
    {
      break;
    }
  }
  return seeds;
}

double medianFiniteRange(const std::vector<Reading>& readings)
{
  std::vector<double> finite;
  for (const Reading& r : readings)
  {
    if (std::isfinite(r.range))
    {
      finite.push_back(r.range);
    }
  }
  if (finite.empty())
  {
    return 1.0;
  }
  std::nth_element(finite.begin(), finite.begin() + finite.size() / 2, finite.end());
  return finite[finite.size() / 2];
}
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
  last_leaves_ = search.result().leaves;
  result.times.total = secondsSince(start);
  return result;
}

void AdaptiveEngine::localizeFixed(AdaptiveSearch& search, const std::vector<Reading>& readings, int level,
                                   Result& result)
{
  const std::int64_t theta_cells = std::max<std::int64_t>(1, std::llround(kTwoPi / cell_theta_));
  const int threads = options_.threads > 0 ? options_.threads : omp_get_max_threads();
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
  const int k = static_cast<int>(readings.size());
  const bool automatic = options_.min_inliers <= 0;
  const int lowest = automatic ? 3 : options_.min_inliers;
  const std::int64_t theta_cells = std::max<std::int64_t>(1, std::llround(kTwoPi / cell_theta_));
  const int threads = options_.threads > 0 ? options_.threads : omp_get_max_threads();

  RefinementSettings settings;
  settings.agreement_tolerance = options_.agreement_tolerance;
  settings.robust_scale =
      std::max(options_.agreement_tolerance, 0.5 * cell_xy_ + 0.5 * cell_theta_ * medianFiniteRange(readings));
  settings.noise_sigma = std::max(options_.range_tolerance / std::sqrt(3.0), 1e-4);
  settings.seed_position_error = 1.5 * cell_xy_;
  settings.seed_angle_error = cell_theta_;
  // Seeds where fewer than (level - 2) readings agree even this loosely are not polished.
  const double loose_gate = 3.0 * settings.robust_scale;

  std::vector<Candidate> seeds;
  int used_level = lowest;
  for (int level = k; level >= lowest; --level)
  {
    auto stage = std::chrono::steady_clock::now();
    const AdaptiveSearchResult& found = search.run(level);
    result.times.preimages += secondsSince(stage);
    stage = std::chrono::steady_clock::now();
    const std::vector<LeafCluster> plateaus = leafMaxima(found.leaves, level, theta_cells);
    result.times.components += secondsSince(stage);
    // Seeds: the best-agreeing distinct leaves of each plateau (a copy of the plateau per seed).
    stage = std::chrono::steady_clock::now();
    std::vector<std::vector<Pose2>> plateau_seeds(plateaus.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (plateaus.size() >= 4)
    for (long c = 0; c < static_cast<long>(plateaus.size()); ++c)
    {
      plateau_seeds[c] =
          plateauSeeds(*map_, found.leaves, plateaus[c], readings, loose_gate, 4.0 * cell_xy_, 4.0 * cell_theta_,
                       plateaus[c].members.size() >= kLargePlateau ? kSeedsPerPlateau : 1);
    }
    std::vector<LeafCluster> maxima;
    for (std::size_t c = 0; c < plateaus.size(); ++c)
    {
      for (const Pose2& seed : plateau_seeds[c])
      {
        maxima.push_back(plateaus[c]);
        maxima.back().centroid = seed;
      }
    }
    result.times.verification += secondsSince(stage);

    const std::size_t first = seeds.size();
    seeds.resize(first + maxima.size());
    std::vector<std::vector<bool>> hypotheses(maxima.size());
    std::vector<char> plausible(maxima.size(), 0);
    std::vector<Pose2> starts(maxima.size());
    stage = std::chrono::steady_clock::now();
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (maxima.size() >= 4)
    for (long c = 0; c < static_cast<long>(maxima.size()); ++c)
    {
      hypotheses[c] = hypothesisOf(found.leaves[maxima[c].representative], readings.size());
      starts[c] = maxima[c].centroid;
      seeds[first + c] = verifiedCandidate(*map_, starts[c], readings, options_.agreement_tolerance);
      plausible[c] = evaluatePose(*map_, starts[c], readings, loose_gate).inliers >= level - 2;
    }
    result.times.verification += secondsSince(stage);

    stage = std::chrono::steady_clock::now();
    RefinementSettings level_settings = settings;
    level_settings.escape_min_inliers = std::max(3, level - 1);
    level_settings.target_inliers = level;
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (maxima.size() >= 4)
    for (long c = 0; c < static_cast<long>(maxima.size()); ++c)
    {
      if (plausible[c])
      {
        seeds[first + c] = refineSeed(*map_, starts[c], readings, hypotheses[c], level_settings);
      }
    }
    // No seed explains as many readings as this level promises: a seed may sit behind an
    // occlusion edge. Retry the first ones with a local lattice search and from other leaves.
    const bool reached =
        std::any_of(seeds.begin(), seeds.end(), [&](const Candidate& s) { return s.inliers >= level; });
    if (!reached)
    {
      const long retried = std::min<long>(static_cast<long>(maxima.size()), kRetriedSeeds);
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (retried >= 4)
      for (long c = 0; c < retried; ++c)
      {
        Candidate& seed = seeds[first + c];
        const LeafCluster& cluster = maxima[c];
        if (c < kLocallySearchedSeeds)
        {
          RefinementSettings local = level_settings;
          local.local_search_cells = 2;
          local.local_search_step = 0.5 * cell_xy_;
          local.local_search_angle_step = 0.5 * cell_theta_;
          Candidate retry = refineSeed(*map_, cluster.centroid, readings, hypotheses[c], local);
          if (betterCandidate(retry, seed))
          {
            seed = std::move(retry);
          }
        }
        const std::size_t n = cluster.members.size();
        const Pose2 others[3] = { found.leaves[cluster.representative].box.centre(),
                                  found.leaves[cluster.members[n / 3]].box.centre(),
                                  found.leaves[cluster.members[(2 * n) / 3]].box.centre() };
        for (const Pose2& other : others)
        {
          if (seed.inliers >= level)
          {
            break;
          }
          Candidate retry = refineSeed(*map_, other, readings, hypotheses[c], level_settings);
          if (betterCandidate(retry, seed))
          {
            seed = std::move(retry);
          }
        }
      }
    }
    result.times.polish += secondsSince(stage);
    for (std::size_t c = 0; c < maxima.size(); ++c)
    {
      seeds[first + c].support = static_cast<double>(maxima[c].size);
    }

    if (found.truncated)
    {
      used_level = level;
      break;
    }
    if (automatic)
    {
      if (std::any_of(seeds.begin(), seeds.end(), [&](const Candidate& s) { return s.inliers >= level; }))
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
      std::copy_if(seeds.begin(), seeds.end(), std::back_inserter(strong),
                   [&](const Candidate& s) { return s.inliers >= level; });
      if (static_cast<int>(rankAndDeduplicate(std::move(strong), options_.uniqueness_distance,
                                              options_.uniqueness_angle, options_.max_candidates)
                               .size()) >= options_.max_candidates)
      {
        break;
      }
    }
  }
  result.min_inliers_used = automatic ? used_level : options_.min_inliers;
  std::vector<Candidate> kept;
  std::copy_if(std::make_move_iterator(seeds.begin()), std::make_move_iterator(seeds.end()), std::back_inserter(kept),
               [&](const Candidate& s) { return s.inliers >= result.min_inliers_used; });
  result.candidates = rankAndDeduplicate(std::move(kept), options_.uniqueness_distance, options_.uniqueness_angle,
                                         options_.max_candidates);
}

AdaptiveEngine::AdaptiveEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options)
  : map_(std::move(map)), options_(options)
{
  const Vec2 size = map_->map().bounds().size();
  cell_xy_ = std::max(size.x(), size.y()) / options_.resolution;
  const int nt = options_.theta_resolution > 0 ? options_.theta_resolution : options_.resolution;
  cell_theta_ = kTwoPi / nt;
  occupancy_ = std::make_shared<const BoxOccupancy>(*map_, cell_xy_, kOccupancyCells);
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

}  // namespace core
}  // namespace fdml_localization
