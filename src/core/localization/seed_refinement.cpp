// refineSeed(): from a seed pose and a hypothesis, the best pose the polish reaches (annealing,
// obstacle-hit hypotheses, lattice search, inlier rounds, leave-one-out escapes, multi-start).
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
bool evaluationBetter(const PoseEvaluation& a, const PoseEvaluation& b)
{
  return rankedBefore(a.inliers, a.contradicted, a.rms, b.inliers, b.contradicted, b.rms);
}
}  // namespace

/// Adopts a polished pose (or a shorter step to it) explaining more readings or a lower RMS.
bool Refiner::consider(const PolishOutcome& polished, bool pull_back)
{
  PoseEvaluation eval = evaluatePose(map_, polished.pose, readings_, settings_.agreement_tolerance);
  if (collecting_)
  {
    reached_.push_back(candidateFrom(polished.pose, eval));
    reached_.back().covariance = polished.covariance;
  }
  if (!evaluationBetter(eval, best_))
  {
    return pull_back && eval.contradicted > best_.contradicted && pullBack(polished);
  }
  best_ = std::move(eval);
  best_pose_ = polished.pose;
  best_cov_ = polished.covariance;
  return true;
}

/// The polish does not see walls its rays newly hit (nor no-returns outside its bounds): a step
/// from the best pose that contradicts more readings is tried again at fractions of its length.
bool Refiner::pullBack(const PolishOutcome& polished)
{
  const Pose2 from = best_pose_;
  PolishOutcome shorter = polished;
  for (double t : { 0.75, 0.5, 0.25 })
  {
    shorter.pose = Pose2(from.x + t * (polished.pose.x - from.x), from.y + t * (polished.pose.y - from.y),
                         wrapAngle(from.theta + t * angleDiff(polished.pose.theta, from.theta)));
    if (consider(shorter, false))
    {
      return true;
    }
  }
  return false;
}

/// Every polish also keeps clear the no-returns the hypothesis or the best pose counts as agreeing
/// (polishPose()'s one-sided bounds): with 2 finite readings of 10 and 8 short no-returns, the
/// polish otherwise slides along the finite readings' continuum past the walls they exclude.
PolishOutcome Refiner::polish(const Pose2& start, const std::vector<bool>& use, double scale) const
{
  std::vector<bool> bounded = use;
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    bounded[i] = bounded[i] || (!std::isfinite(readings_[i].range) && (hypothesis_[i] || best_.inlier_mask[i]));
  }
  return polishPose(map_, start, readings_, bounded, scale, settings_.max_iterations, settings_.noise_sigma,
                    settings_.prior);
}

/// Graduated robustness: the Cauchy scale shrinks from about the seed's error to eps, so
/// readings cut short by unknown obstacles lose their pull as the pose settles.
void Refiner::annealFrom(const Pose2& start, const std::vector<bool>& use)
{
  const double eps = settings_.agreement_tolerance;
  PolishOutcome stage;
  stage.pose = start;
  for (double scale = settings_.robust_scale;; scale *= 0.4)
  {
    const double s = std::max(scale, eps);
    stage = polish(stage.pose, use, s);
    if (s <= eps)
    {
      break;
    }
  }
  consider(stage);
}

/// The finite-range inliers of the best pose, without reading @p drop (-1: none).
std::vector<bool> Refiner::finiteInliers(int drop) const
{
  std::vector<bool> use(readings_.size(), false);
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    use[i] = best_.inlier_mask[i] && std::isfinite(readings_[i].range) && static_cast<int>(i) != drop;
  }
  return use;
}

/// First polish: robust, on the hypothesis minus the readings whose rays pass a vertex within
/// the seed's uncertainty (most suspect first), keeping at least 4 readings; then on all of it.
void Refiner::firstPolish()
{
  const std::vector<double> margins = vertexMargins(map_, seed_, readings_, settings_.seed_angle_error);
  std::vector<int> used;
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    if (hypothesis_[i] && std::isfinite(readings_[i].range))
    {
      used.push_back(static_cast<int>(i));
    }
  }
  std::sort(used.begin(), used.end(), [&](int a, int b) { return margins[a] < margins[b]; });
  std::vector<bool> use = hypothesis_;
  int remaining = static_cast<int>(used.size());
  for (int i : used)
  {
    if (remaining <= 4 || margins[i] >= settings_.seed_position_error)
    {
      break;
    }
    use[i] = false;
    --remaining;
  }
  annealFrom(seed_, use);
  if (use != hypothesis_)
  {
    annealFrom(seed_, hypothesis_);
  }
}

/// Unknown obstacles only ever shorten readings: the readings measured shortest relative to what
/// the map predicts at the seed are the likeliest obstacle hits. While the best pose does not
/// explain target_inliers readings, leave out the 1, 2, ... most shortened ones.
void Refiner::dropShortened()
{
  std::vector<int> shortened;
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    const double r = seed_residuals_[i];
    if (hypothesis_[i] && std::isfinite(r) && r > settings_.agreement_tolerance)
    {
      shortened.push_back(static_cast<int>(i));
    }
  }
  std::sort(shortened.begin(), shortened.end(), [&](int a, int b) {
    return seed_residuals_[a] / std::max(readings_[a].range, 1e-3) >
           seed_residuals_[b] / std::max(readings_[b].range, 1e-3);
  });
  std::vector<bool> trimmed = hypothesis_;
  int kept = countUsed(hypothesis_);
  for (std::size_t j = 0; j < shortened.size() && j < static_cast<std::size_t>(settings_.max_dropped_shortened) &&
                          best_.inliers < settings_.target_inliers && kept > 4;
       ++j)
  {
    trimmed[shortened[j]] = false;
    --kept;
    annealFrom(seed_, trimmed);
  }
}

/// Still short of the target: the seed may sit across occlusion edges from the optimum, where
/// no descent reaches it. Search a small lattice around the seed for the pose where the most
/// readings roughly agree, and polish from there on those readings.
void Refiner::localSearch()
{
  if (settings_.local_search_cells <= 0 || best_.inliers >= settings_.target_inliers)
  {
    return;
  }
  const int m = settings_.local_search_cells;
  const double tol = 0.5 * settings_.robust_scale;
  Pose2 best_start = seed_;
  PoseEvaluation best_rough = evaluatePose(map_, seed_, readings_, tol);
  for (int a = -m; a <= m; ++a)
  {
    for (int b = -m; b <= m; ++b)
    {
      for (int c = -m; c <= m; ++c)
      {
        const Pose2 p(seed_.x + a * settings_.local_search_step, seed_.y + b * settings_.local_search_step,
                      wrapAngle(seed_.theta + c * settings_.local_search_angle_step));
        PoseEvaluation rough = evaluatePose(map_, p, readings_, tol);
        if (rough.inliers > best_rough.inliers)
        {
          best_rough = std::move(rough);
          best_start = p;
        }
      }
    }
  }
  std::vector<bool> use = best_rough.inlier_mask;
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    use[i] = use[i] && std::isfinite(readings_[i].range);
  }
  if (countUsed(use) >= 3)
  {
    annealFrom(best_start, use);
  }
}

/// Re-polishes on the current inliers while that improves the consensus.
void Refiner::polishRounds()
{
  for (int round = 0; round < settings_.max_rounds; ++round)
  {
    const std::vector<bool> use = finiteInliers(-1);
    if (countUsed(use) < 3)
    {
      return;
    }
    const std::vector<bool> before = best_.inlier_mask;
    if (!consider(polish(best_pose_, use, 0.0)) || best_.inlier_mask == before)
    {
      return;
    }
  }
}

Candidate Refiner::candidate() const
{
  Candidate c = candidateFrom(best_pose_, best_);
  // The seed itself, when no polish beat it (no three finite readings to polish on, or an exact
  // start), has no covariance yet: a zero one would be a false certainty.
  c.covariance = best_cov_;
  ensureCovariance(map_, readings_, settings_.noise_sigma, c);
  return c;
}

Candidate refineSeed(const MapRayCaster& map, const Pose2& seed, const std::vector<Reading>& readings,
                     const std::vector<bool>& hypothesis, const RefinementSettings& settings,
                     const std::vector<Pose2>& region_starts, std::vector<Candidate>* ties)
{
  Refiner refiner(map, seed, readings, hypothesis, settings, region_starts);
  refiner.firstPolish();
  refiner.dropShortened();
  refiner.localSearch();
  refiner.polishRounds();
  refiner.escapes();
  refiner.multiStart();
  if (ties != nullptr)
  {
    *ties = refiner.ties();
  }
  return refiner.candidate();
}

}  // namespace core
}  // namespace fdml_localization
