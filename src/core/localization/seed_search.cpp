#include "fdml_localization/core/localization/seed_search.h"

#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/seed_refiner.h"
#include "fdml_localization/core/util/stopwatch.h"

#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Seeds retried from other poses of their region when no seed reaches a level ...
constexpr std::size_t kRetriedSeeds = 32;
/// ... of which this many first get a local lattice search around their start.
constexpr std::size_t kLocallySearchedSeeds = 8;

/// What refining a seed needs.
struct SearchContext
{
  const MapRayCaster& map;
  const std::vector<Reading>& readings;
  SeedScale scale;
  RefinementSettings settings;
  double loose_gate = 0.0;  ///< agreement band of the rough count at a seed's start [m]
  int threads = 1;
  /// LocalizerOptions::deadline from the search's start: seeds not yet refined by then are left
  /// unrefined.
  Deadline deadline;
};

/// The seeds and what became of them, in the order they were supplied.
class SeedPool
{
public:
  explicit SeedPool(const SearchContext& ctx) : ctx_(ctx)
  {}

  /// Adds @p seeds and verifies them at their starts.
  void add(std::vector<SearchSeed> seeds)
  {
    const long first = static_cast<long>(seeds_.size());
    std::move(seeds.begin(), seeds.end(), std::back_inserter(seeds_));
    const long n = static_cast<long>(seeds_.size());
    candidates_.resize(n);
    rough_.resize(n, 0);
    refined_.resize(n, 0);
    retried_.resize(n, 0);
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx_.threads) if (n - first >= 4)
    for (long c = first; c < n; ++c)
    {
      const Pose2& start = seeds_[c].start;
      const std::vector<double> residuals = poseResiduals(ctx_.map, start, ctx_.readings);
      candidates_[c] =
          candidateFrom(start, evaluateResiduals(residuals, ctx_.readings, ctx_.settings.agreement_tolerance));
      rough_[c] = evaluateResiduals(residuals, ctx_.readings, ctx_.loose_gate).inliers;
      // Near a depth discontinuity (a ray grazing a corner) a few centimetres change a range
      // by metres: the region's other poses may agree where its centre does not. Start where
      // the most readings roughly agree.
      for (const Pose2& other : seeds_[c].retry_starts)
      {
        const int rough = evaluatePose(ctx_.map, other, ctx_.readings, ctx_.loose_gate).inliers;
        if (rough > rough_[c])
        {
          rough_[c] = rough;
          seeds_[c].start = other;
        }
      }
    }
  }

  /// The most inliers of any candidate so far.
  int best() const
  {
    return std::accumulate(candidates_.begin(), candidates_.end(), 0,
                           [](int m, const Candidate& c) { return std::max(m, c.inliers); });
  }

  /// The largest net consensus (inliers - contradicted readings) of any candidate so far.
  int bestNet() const
  {
    return std::accumulate(candidates_.begin(), candidates_.end(), 0,
                           [](int m, const Candidate& c) { return std::max(m, netConsensus(c)); });
  }

  /// Distinct candidates reaching @p level net, ranked.
  std::size_t distinctReaching(int level, const LocalizerOptions& options) const
  {
    std::vector<Candidate> strong;
    std::copy_if(candidates_.begin(), candidates_.end(), std::back_inserter(strong),
                 [&](const Candidate& c) { return netConsensus(c) >= level; });
    return rankAndDeduplicate(std::move(strong), options.uniqueness_distance, options.uniqueness_angle,
                              options.max_candidates)
        .size();
  }

  /// Refines, once, every seed that could reach @p level: its region explains as many readings
  /// and at least level - 2 of them roughly agree at its start.
  void refineFor(int level)
  {
    const RefinementSettings with = levelSettings(level);
    const long n = static_cast<long>(seeds_.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx_.threads) if (n >= 4)
    for (long c = 0; c < n; ++c)
    {
      if (!refined_[c] && seeds_[c].promised >= level && rough_[c] >= level - 2 && !ctx_.deadline.passed())
      {
        refined_[c] = 1;
        keepBetter(c, refineSeed(ctx_.map, seeds_[c].start, ctx_.readings, seeds_[c].hypothesis, with));
      }
    }
  }

  /// Refines, once, the @p most seeds promising @p level not yet refined, most agreeing first.
  void refineRemaining(int level, std::size_t most)
  {
    std::vector<long> order;
    for (long c = 0; c < static_cast<long>(seeds_.size()); ++c)
    {
      if (!refined_[c] && seeds_[c].promised >= level)
      {
        order.push_back(c);
      }
    }
    std::stable_sort(order.begin(), order.end(), [&](long a, long b) { return rough_[a] > rough_[b]; });
    order.resize(std::min(order.size(), most));
    const RefinementSettings with = levelSettings(level);
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx_.threads) if (order.size() >= 4)
    for (std::size_t j = 0; j < order.size(); ++j)
    {
      const long c = order[j];
      refined_[c] = 1;
      keepBetter(c, refineSeed(ctx_.map, seeds_[c].start, ctx_.readings, seeds_[c].hypothesis, with));
    }
  }

  /**
   * @brief Second chances for the seeds that promise @p level but fell short: the optimum may
   *        lie across an occlusion edge from the start, where no descent reaches it, or far from
   *        it in a large region. The most promising (most readings, then most rough agreement)
   *        get a local lattice search and restarts from other poses of their region; a fixed
   *        number, so the result does not depend on thread timing.
   */
  void retryFor(int level, std::size_t retried = kRetriedSeeds, std::size_t searched = kLocallySearchedSeeds)
  {
    const std::vector<long> order = retryOrder(level, retried);
    const RefinementSettings with = levelSettings(level);
    RefinementSettings search = with;
    search.local_search_cells = 2;
    search.local_search_step = 0.5 * ctx_.scale.cell_xy;
    search.local_search_angle_step = 0.5 * ctx_.scale.cell_theta;
    search.multi_start = 1;
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx_.threads) if (order.size() >= 2)
    for (std::size_t j = 0; j < order.size(); ++j)
    {
      const long c = order[j];
      retried_[c] = 1;
      const SearchSeed& seed = seeds_[c];
      if (j < searched)
      {
        keepBetter(c, refineSeed(ctx_.map, seed.start, ctx_.readings, seed.hypothesis, search));
      }
      for (const Pose2& start : seed.retry_starts)
      {
        if (netConsensus(candidates_[c]) < level)
        {
          keepBetter(c, refineSeed(ctx_.map, start, ctx_.readings, seed.hypothesis, with));
        }
      }
    }
  }

  /// The candidates explaining at least @p level readings, ranked, those tied at the best net
  /// consensus polished from their region's poses and a lattice around them (multi-start) so
  /// that they reach their region's optimum, with their seeds' regions.
  SeedSearchOutcome ranked(int level, const LocalizerOptions& options)
  {
    std::vector<Candidate> kept;
    for (std::size_t c = 0; c < candidates_.size(); ++c)
    {
      if (candidates_[c].inliers >= level)
      {
        // The seed's index rides in support until the duplicates are gone.
        candidates_[c].support = static_cast<double>(c);
        kept.push_back(std::move(candidates_[c]));
      }
    }
    kept = rankAndDeduplicate(std::move(kept), options.uniqueness_distance, options.uniqueness_angle,
                              options.max_candidates);
    polishTop(level, options, kept);
    SeedSearchOutcome outcome;
    outcome.min_inliers_used = level;
    outcome.candidates = rankAndAbsorbDuplicates(kept, options.uniqueness_distance, options.uniqueness_angle,
                                                 ctx_.settings.noise_sigma, options.max_candidates);
    for (Candidate& candidate : outcome.candidates)
    {
      const SearchSeed& seed = seeds_[static_cast<std::size_t>(candidate.support)];
      outcome.regions.push_back(seed.region);
      candidate.support = seed.support;
    }
    return outcome;
  }

private:
  /// The candidates tied at the best net consensus get the multi-start, which adds the other optima
  /// of their regions tying them (polishTiedCandidate(); the first of each region enumerates it
  /// when it holds several); every candidate gets its covariance widened along continua.
  void polishTop(int level, const LocalizerOptions& options, std::vector<Candidate>& kept) const
  {
    RefinementSettings with = levelSettings(level);
    with.multi_start = 1;
    with.collect_ties = true;
    const int top = kept.empty() ? 0 : netConsensus(kept.front());
    std::vector<char> first_of_region(kept.size(), 0);
    std::vector<std::size_t> regions;
    for (std::size_t j = 0; j < kept.size(); ++j)
    {
      const std::size_t region = seeds_[static_cast<std::size_t>(kept[j].support)].region;
      if (netConsensus(kept[j]) >= top && std::find(regions.begin(), regions.end(), region) == regions.end())
      {
        regions.push_back(region);
        first_of_region[j] = 1;
      }
    }
    std::vector<std::vector<Candidate>> ties(kept.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(ctx_.threads) if (kept.size() >= 2)
    for (std::size_t j = 0; j < kept.size(); ++j)
    {
      // A seed's start no refinement beat (an exact start, or no three finite readings).
      ensureCovariance(ctx_.map, ctx_.readings, ctx_.settings.noise_sigma, kept[j]);
      if (netConsensus(kept[j]) < top)
      {
        settleAlongContinua(ctx_.map, ctx_.readings, ctx_.settings, kept[j]);
        continue;
      }
      ties[j] = polishTiedCandidate(ctx_.map, ctx_.readings, seeds_[static_cast<std::size_t>(kept[j].support)], with,
                                    options, ctx_.loose_gate, first_of_region[j] != 0, ctx_.deadline, kept[j]);
    }
    for (std::vector<Candidate>& found : ties)
    {
      std::move(found.begin(), found.end(), std::back_inserter(kept));
    }
  }

  std::vector<long> retryOrder(int level, std::size_t retried) const
  {
    std::vector<long> order;
    for (long c = 0; c < static_cast<long>(seeds_.size()); ++c)
    {
      if (!retried_[c] && seeds_[c].promised >= level && netConsensus(candidates_[c]) < level)
      {
        order.push_back(c);
      }
    }
    std::stable_sort(order.begin(), order.end(), [&](long a, long b) {
      return seeds_[a].promised != seeds_[b].promised ? seeds_[a].promised > seeds_[b].promised : rough_[a] > rough_[b];
    });
    order.resize(std::min(order.size(), retried));
    return order;
  }

  RefinementSettings levelSettings(int level) const
  {
    RefinementSettings with = ctx_.settings;
    with.escape_min_inliers = std::max(3, level - 1);
    with.target_inliers = level;
    return with;
  }

  void keepBetter(long c, Candidate candidate)
  {
    if (betterCandidate(candidate, candidates_[c]))
    {
      candidates_[c] = std::move(candidate);
    }
  }

  const SearchContext& ctx_;
  std::vector<SearchSeed> seeds_;
  std::vector<Candidate> candidates_;
  std::vector<int> rough_;  ///< readings agreeing within the loose gate at the start
  std::vector<char> refined_;
  std::vector<char> retried_;
};

SearchContext makeContext(const MapRayCaster& map, const std::vector<Reading>& readings,
                          const LocalizerOptions& options, const SeedScale& scale)
{
  SearchContext ctx{ map, readings, scale, RefinementSettings(), 0.0, 1, Deadline(options.deadline) };
  ctx.threads = threadsFor(options.threads);
  ctx.settings.agreement_tolerance = options.agreement_tolerance;
  ctx.settings.robust_scale = seedGate(readings, options, scale) / 3.0;
  ctx.settings.noise_sigma = std::max(options.range_tolerance / std::sqrt(3.0), 1e-4);
  ctx.settings.seed_position_error = 1.5 * scale.cell_xy;
  ctx.settings.seed_angle_error = scale.cell_theta;
  ctx.settings.multi_start_step = scale.cell_xy;
  ctx.settings.multi_start_angle_step = scale.cell_theta;
  // Seeds where fewer than (level - 2) readings agree even this loosely are not polished.
  ctx.loose_gate = seedGate(readings, options, scale);
  return ctx;
}

/// Second chances after the levels: returns the k' finally used.
int secondChances(SeedPool& pool, bool automatic, bool reached, int used_level, int lowest, int k)
{
  if (!automatic)
  {
    if (pool.best() < lowest)
    {
      pool.retryFor(lowest);
    }
    return lowest;
  }
  // One level above what was reached (a larger consensus may have been missed), or at the
  // lowest level when nothing reached it.
  for (int target = reached ? used_level + 1 : lowest; target <= k; target = used_level + 1)
  {
    pool.retryFor(target);
    if (pool.bestNet() < target)
    {
      break;
    }
    used_level = pool.bestNet();
  }
  // Ties: the truth's region may promise as much as a place that reached the level first.
  pool.refineRemaining(used_level, kRetriedSeeds);
  return used_level;
}
}  // namespace

SeedSearchOutcome robustSearch(SeedSource& source, const MapRayCaster& map, const std::vector<Reading>& readings,
                               const LocalizerOptions& options, const SeedScale& scale, StageTimes& times)
{
  const int k = static_cast<int>(readings.size());
  const bool automatic = options.min_inliers <= 0;
  const int lowest = automatic ? 3 : options.min_inliers;
  const SearchContext ctx = makeContext(map, readings, options, scale);
  SeedPool pool(ctx);
  int used_level = lowest;
  bool reached = false;
  bool out_of_time = false;
  for (int level = k; level >= lowest && !reached && !out_of_time && !source.exhausted(); --level)
  {
    std::vector<SearchSeed> seeds = source.seedsAt(level);
    auto stage = std::chrono::steady_clock::now();
    pool.add(std::move(seeds));
    times.verification += secondsSince(stage);
    stage = std::chrono::steady_clock::now();
    pool.refineFor(level);
    times.polish += secondsSince(stage);
    if (automatic)
    {
      // Maximum consensus: the first level some seed reaches, net of the readings its pose
      // contradicts (a pose where a reading passes through a wall must explain one more).
      reached = pool.bestNet() >= level || source.exhausted();
      used_level = reached ? level : used_level;
    }
    else if (level > lowest)
    {
      // Fixed k': once max_candidates distinct poses reach `level` net, the lower levels' seeds
      // (which promise fewer) cannot enter the ranked list.
      reached = static_cast<int>(pool.distinctReaching(level, options)) >= options.max_candidates;
    }
    // The deadline (LocalizerOptions) stops the descent: the candidates found so far are ranked.
    out_of_time = !reached && ctx.deadline.passed();
  }
  if (out_of_time)
  {
    return pool.ranked(automatic ? std::max(lowest, pool.bestNet()) : options.min_inliers, options);
  }
  const auto stage = std::chrono::steady_clock::now();
  const int level = secondChances(pool, automatic, reached && pool.bestNet() >= used_level, used_level, lowest, k);
  times.polish += secondsSince(stage);
  return pool.ranked(automatic ? level : options.min_inliers, options);
}

}  // namespace core
}  // namespace fdml_localization
