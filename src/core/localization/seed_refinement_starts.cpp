// refineSeed()'s later steps (seed_refiner.h): leave-one-out escapes from false minima, the
// fine polish across a grazing reading's jump, the multi-start over the region, and the final
// polish of the best candidates (polishTiedCandidate()).
#include "fdml_localization/core/localization/seed_refiner.h"

#include <algorithm>
#include <cmath>
#include <iterator>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Cauchy scale [m] of Refiner::fineFrom()'s polish: about a good range sensor's noise.
constexpr double kFineScale = 0.002;
/// At most this many polishes enumerate an ambiguous region (Refiner::enumerate()): about
/// 25 ms with a few finite readings.
constexpr std::size_t kRegionPolishes = 512;

/// The reading of @p among with the largest finite residual at @p e (the first of equals); -1
/// when there is none.
int largestResidual(const PoseEvaluation& e, const std::vector<bool>& among)
{
  int worst = -1;
  for (std::size_t i = 0; i < among.size(); ++i)
  {
    if (among[i] && std::isfinite(e.residuals[i]) &&
        (worst < 0 || std::abs(e.residuals[i]) > std::abs(e.residuals[static_cast<std::size_t>(worst)])))
    {
      worst = static_cast<int>(i);
    }
  }
  return worst;
}
}  // namespace

/// A reading whose ray grazes a vertex at the optimum jumps there, and its jump holds a
/// polish away from the optimum (a heading mirrored about a wall's normal explains the other
/// readings almost as well). Polish at a fine Cauchy scale, which discounts the jump, then
/// again without the reading left worst; keep whatever improves.
void Refiner::fineFrom(const Pose2& start, const std::vector<bool>& use)
{
  const PolishOutcome fine = polish(start, use, kFineScale);
  consider(fine);
  const int worst = largestResidual(evaluatePose(map_, fine.pose, readings_, settings_.agreement_tolerance), use);
  if (worst < 0)
  {
    return;
  }
  std::vector<bool> rest = use;
  rest[static_cast<std::size_t>(worst)] = false;
  if (countUsed(rest) >= 3)
  {
    consider(polish(fine.pose, rest, 0.0));
  }
}

/// Rays this close in heading [rad] on the robot are one sensor's (driving, successive readings)
/// or alike: they cross an occlusion edge together.
constexpr double kParallelRays = 0.035;

bool parallelRays(const Reading& a, const Reading& b)
{
  return std::abs(wrapAngle(a.offset.theta - b.offset.theta)) < kParallelRays;
}

std::vector<bool> Refiner::withoutParallel(int drop) const
{
  std::vector<bool> use = finiteInliers(drop);
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    use[i] = use[i] && !parallelRays(readings_[i], readings_[static_cast<std::size_t>(drop)]);
  }
  return use;
}

/// The readings to leave out in one escape round: the worst one, then those passing nearest a
/// vertex (with @p one_per_direction, none parallel to one before it); empty when fewer than 4
/// finite inliers remain.
std::vector<int> Refiner::escapeTries(bool one_per_direction) const
{
  std::vector<int> order;
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    if (best_.inlier_mask[i] && std::isfinite(readings_[i].range))
    {
      order.push_back(static_cast<int>(i));
    }
  }
  if (order.size() < 4)
  {
    return {};
  }
  const std::vector<double> margins = vertexMargins(map_, best_pose_, readings_, settings_.seed_angle_error);
  const int worst = largestResidual(best_, finiteInliers(-1));
  std::vector<int> tries{ worst };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return margins[a] < margins[b]; });
  for (std::size_t j = 0; j < order.size() && static_cast<int>(tries.size()) < settings_.escape_tries; ++j)
  {
    const Reading& reading = readings_[static_cast<std::size_t>(order[j])];
    const bool repeated = std::any_of(tries.begin(), tries.end(), [&](int t) {
      return t == order[j] || (one_per_direction && parallelRays(readings_[static_cast<std::size_t>(t)], reading));
    });
    if (!repeated)
    {
      tries.push_back(order[j]);
    }
  }
  return tries;
}

/// The ray-cast cost is only piecewise smooth: a reading whose ray crosses an occlusion edge
/// between here and the optimum can hold the polish in a false minimum. Leave out, one at a
/// time, the readings passing nearest to a vertex and the worst one, each then with the readings
/// parallel to it, and keep the result when the consensus improves (verification seed 842: two
/// front rays of a robot driving crossed a wall's step 1.8 cm deep together, and leaving out either
/// alone kept the polish 1.75 deg from the exact truth).
void Refiner::escapes()
{
  for (int attempt = 0;
       attempt < settings_.max_escapes && best_.rms > 1e-9 && best_.inliers >= settings_.escape_min_inliers; ++attempt)
  {
    const std::vector<int> tries = escapeTries(false);
    bool improved = false;
    for (std::size_t j = 0; j < tries.size() && !improved; ++j)
    {
      const std::vector<bool> alone = finiteInliers(tries[j]);
      improved = consider(polish(best_pose_, alone, 0.0));
      // Its parallel siblings can hold the false minimum as firmly: left out with it.
      const std::vector<bool> rest = improved ? alone : withoutParallel(tries[j]);
      if (countUsed(rest) >= 3 && countUsed(rest) < countUsed(alone))
      {
        improved = consider(polish(best_pose_, rest, 0.0));
      }
    }
    improved = improved || (settings_.escape_pairs && escapePairs());
    if (!improved)
    {
      break;
    }
    polishRounds();
  }
}

bool Refiner::escapePairs()
{
  const std::vector<int> tries = escapeTries(true);
  for (std::size_t j = 0; j < tries.size(); ++j)
  {
    const std::vector<bool> first = withoutParallel(tries[j]);
    for (std::size_t l = j + 1; l < tries.size(); ++l)
    {
      std::vector<bool> rest = first;
      const std::vector<bool> second = withoutParallel(tries[l]);
      for (std::size_t i = 0; i < rest.size(); ++i)
      {
        rest[i] = rest[i] && second[i];
      }
      if (countUsed(rest) >= 3 && consider(polish(best_pose_, rest, 0.0)))
      {
        return true;
      }
    }
  }
  return false;
}

/// The polish is a local descent: the optimum of the region can lie in another basin of the
/// piecewise-smooth cost. Polish (Cauchy at eps, on the hypothesis's finite readings and the
/// best pose's inliers) from every pose of a lattice around the best pose, anneal from every
/// given pose of the region, keep the best.
void Refiner::multiStart()
{
  const int m = settings_.multi_start;
  const bool exact = best_.rms <= 1e-9 && best_.inliers == static_cast<int>(readings_.size());
  if (m <= 0 || (exact && !settings_.collect_ties))
  {
    return;
  }
  const std::vector<bool> use = hypothesisAndInliers();
  if (countUsed(use) < 3)
  {
    return;
  }
  collecting_ = settings_.collect_ties;
  for (const Pose2& start : region_starts_)
  {
    annealFrom(start, use);
  }
  // The lattice goes around the best pose so far, a region start's if one was better: around the
  // refined seed only, a better place found from the region went without one (verification seed
  // 875: the seed settled on an inexact place, a region start reached an exact one 25 cm from it,
  // and the exact truth 9.6 cm from that was never polished to).
  const Pose2 centre = best_pose_;
  for (int a = -m; a <= m; ++a)
  {
    for (int b = -m; b <= m; ++b)
    {
      for (int c = -m; c <= m; ++c)
      {
        if (a != 0 || b != 0 || c != 0)
        {
          const Pose2 start(centre.x + a * settings_.multi_start_step, centre.y + b * settings_.multi_start_step,
                            wrapAngle(centre.theta + c * settings_.multi_start_angle_step));
          consider(polish(start, use, settings_.agreement_tolerance));
          if (a == 0 && b == 0)
          {
            fineFrom(start, use);  // the heading's other basins, e.g. mirrored about a wall's normal
          }
        }
      }
    }
  }
  collecting_ = false;
  polishRounds();
}

std::vector<bool> Refiner::hypothesisAndInliers() const
{
  std::vector<bool> use = finiteInliers(-1);
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    use[i] = use[i] || (hypothesis_[i] && std::isfinite(readings_[i].range));
  }
  return use;
}

void Refiner::enumerate(const std::vector<Pose2>& poses, double gate, double reach, const Deadline& deadline)
{
  const std::vector<bool> use = hypothesisAndInliers();
  if (countUsed(use) < 3)
  {
    return;
  }
  std::vector<Pose2> agreeing;
  for (const Pose2& pose : poses)
  {
    const Pose2 start = freeStart(map_, pose, reach);
    if (std::all_of(readings_.begin(), readings_.end(), [&](const Reading& reading) {
          return std::abs(readingResidual(map_, start, reading, gate)) < gate;  // false for NaN
        }))
    {
      agreeing.push_back(start);
    }
  }
  const std::size_t n = agreeing.size();
  const std::size_t polishes = std::min(n, kRegionPolishes);
  collecting_ = true;
  for (std::size_t j = 0; j < polishes && !deadline.passed(); ++j)
  {
    consider(polish(agreeing[j * n / polishes], use, settings_.agreement_tolerance));
  }
  collecting_ = false;
}

std::vector<Candidate> Refiner::ties() const
{
  std::vector<Candidate> tied;
  const int net = best_.inliers - best_.contradicted;
  std::copy_if(reached_.begin(), reached_.end(), std::back_inserter(tied),
               [&](const Candidate& c) { return netConsensus(c) >= net; });
  return tied;
}

namespace
{
/// True when one of @p ties lies beyond the uniqueness margins of @p best.
bool anotherOptimum(const Candidate& best, const std::vector<Candidate>& ties, const LocalizerOptions& options)
{
  return std::any_of(ties.begin(), ties.end(), [&](const Candidate& tie) {
    return !withinMargins(tie.pose, best.pose, options.uniqueness_distance, options.uniqueness_angle);
  });
}
}  // namespace

std::vector<Candidate> polishTiedCandidate(const MapRayCaster& map, const std::vector<Reading>& readings,
                                           const SearchSeed& seed, const RefinementSettings& settings,
                                           const LocalizerOptions& options, double gate, bool enumerate,
                                           const Deadline& deadline, Candidate& candidate)
{
  std::vector<Candidate> ties;
  Candidate polished = refineSeed(map, candidate.pose, readings, seed.hypothesis, settings,
                                  seed.region_starts.empty() ? seed.retry_starts : seed.region_starts, &ties);
  if (enumerate && seed.region_poses && anotherOptimum(polished, ties, options))
  {
    const std::vector<Pose2> none;
    Refiner refiner(map, polished.pose, readings, seed.hypothesis, settings, none);
    refiner.enumerate(*seed.region_poses, gate, 0.5 * settings.multi_start_step, deadline);
    const std::vector<Candidate> more = refiner.ties();
    std::copy(more.begin(), more.end(), std::back_inserter(ties));
    Candidate best = refiner.candidate();
    if (betterCandidate(best, polished))
    {
      polished = std::move(best);
    }
  }
  if (betterCandidate(polished, candidate))
  {
    polished.support = candidate.support;
    candidate = std::move(polished);
  }
  settleAlongContinua(map, readings, settings, candidate);
  // A tie within the uniqueness margins of the candidate is its duplicate, but first widens its
  // covariance to cover it (absorbTiedDuplicates()): de-duplicated among themselves first, the
  // ties could lose the one that is the truth.
  std::vector<Candidate> own{ candidate };
  absorbTiedDuplicates(ties, options.uniqueness_distance, options.uniqueness_angle, settings.noise_sigma, own);
  candidate.covariance = own.front().covariance;
  ties = rankAndDeduplicate(std::move(ties), options.uniqueness_distance, options.uniqueness_angle,
                            options.max_candidates);
  for (Candidate& tie : ties)
  {
    tie.support = candidate.support;
    settleAlongContinua(map, readings, settings, tie);
  }
  return ties;
}

}  // namespace core
}  // namespace fdml_localization
