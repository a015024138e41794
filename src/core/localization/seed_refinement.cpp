// refineSeed(): from a seed pose and a hypothesis, the best pose the polish reaches (annealing,
// obstacle-hit hypotheses, lattice search, inlier rounds, leave-one-out escapes, multi-start).
#include "fdml_localization/core/localization/robust_search.h"

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

int countUsed(const std::vector<bool>& use)
{
  return static_cast<int>(std::count(use.begin(), use.end(), true));
}

/// The state of one refinement: the best pose so far and the steps that try to improve it.
class Refiner
{
public:
  Refiner(const MapRayCaster& map, const Pose2& seed, const std::vector<Reading>& readings,
          const std::vector<bool>& hypothesis, const RefinementSettings& settings,
          const std::vector<Pose2>& region_starts)
    : map_(map)
    , seed_(seed)
    , readings_(readings)
    , hypothesis_(hypothesis)
    , settings_(settings)
    , region_starts_(region_starts)
    , best_pose_(seed)
    , best_(evaluatePose(map, seed, readings, settings.agreement_tolerance))
    , seed_residuals_(best_.residuals)
  {}

  void firstPolish();
  void dropShortened();
  void localSearch();
  void polishRounds();
  void escapes();
  void multiStart();
  Candidate candidate() const;
  std::vector<Candidate> ties() const;  ///< the optima multiStart() reached tying the best

private:
  /// Adopts a polished pose (or a shorter step to it) explaining more readings or a lower RMS.
  bool consider(const PolishOutcome& polished, bool pull_back = true)
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

  /// The polish does not see no-return readings (nor walls its rays newly hit): a step from the
  /// best pose that contradicts more readings is tried again at fractions of its length.
  bool pullBack(const PolishOutcome& polished)
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

  PolishOutcome polish(const Pose2& start, const std::vector<bool>& use, double scale) const
  {
    return polishPose(map_, start, readings_, use, scale, settings_.max_iterations, settings_.noise_sigma);
  }

  /// Graduated robustness: the Cauchy scale shrinks from about the seed's error to eps, so
  /// readings cut short by unknown obstacles lose their pull as the pose settles.
  void annealFrom(const Pose2& start, const std::vector<bool>& use)
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
  std::vector<bool> finiteInliers(int drop) const
  {
    std::vector<bool> use(readings_.size(), false);
    for (std::size_t i = 0; i < readings_.size(); ++i)
    {
      use[i] = best_.inlier_mask[i] && std::isfinite(readings_[i].range) && static_cast<int>(i) != drop;
    }
    return use;
  }

  std::vector<int> escapeTries() const;

  const MapRayCaster& map_;
  const Pose2 seed_;
  const std::vector<Reading>& readings_;
  const std::vector<bool>& hypothesis_;
  const RefinementSettings& settings_;
  const std::vector<Pose2>& region_starts_;
  Pose2 best_pose_;
  PoseEvaluation best_;
  const std::vector<double> seed_residuals_;
  Eigen::Matrix3d best_cov_ = Eigen::Matrix3d::Identity() * 1e6;
  bool collecting_ = false;
  std::vector<Candidate> reached_;  ///< every polish result of multiStart() (collect_ties)
};

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

/// The readings to leave out in one escape round: the worst one, then those passing nearest a
/// vertex; empty when fewer than 4 finite inliers remain.
std::vector<int> Refiner::escapeTries() const
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
  const int worst = *std::max_element(order.begin(), order.end(), [&](int a, int b) {
    return std::abs(best_.residuals[a]) < std::abs(best_.residuals[b]);
  });
  std::vector<int> tries{ worst };
  std::sort(order.begin(), order.end(), [&](int a, int b) { return margins[a] < margins[b]; });
  for (std::size_t j = 0; j < order.size() && static_cast<int>(tries.size()) < settings_.escape_tries; ++j)
  {
    if (order[j] != worst)
    {
      tries.push_back(order[j]);
    }
  }
  return tries;
}

/// The ray-cast cost is only piecewise smooth: a reading whose ray crosses an occlusion edge
/// between here and the optimum can hold the polish in a false minimum. Leave out, one at a
/// time, the readings passing nearest to a vertex and the worst one, and keep the result when
/// the consensus improves.
void Refiner::escapes()
{
  for (int attempt = 0;
       attempt < settings_.max_escapes && best_.rms > 1e-9 && best_.inliers >= settings_.escape_min_inliers; ++attempt)
  {
    const std::vector<int> tries = escapeTries();
    bool improved = false;
    for (std::size_t j = 0; j < tries.size() && !improved; ++j)
    {
      improved = consider(polish(best_pose_, finiteInliers(tries[j]), 0.0));
    }
    if (!improved)
    {
      break;
    }
    polishRounds();
  }
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
  std::vector<bool> use = finiteInliers(-1);
  for (std::size_t i = 0; i < readings_.size(); ++i)
  {
    use[i] = use[i] || (hypothesis_[i] && std::isfinite(readings_[i].range));
  }
  if (countUsed(use) < 3)
  {
    return;
  }
  const Pose2 centre = best_pose_;
  collecting_ = settings_.collect_ties;
  for (const Pose2& start : region_starts_)
  {
    annealFrom(start, use);
  }
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
        }
      }
    }
  }
  collecting_ = false;
  polishRounds();
}

std::vector<Candidate> Refiner::ties() const
{
  std::vector<Candidate> tied;
  const int net = best_.inliers - best_.contradicted;
  std::copy_if(reached_.begin(), reached_.end(), std::back_inserter(tied),
               [&](const Candidate& c) { return netConsensus(c) >= net; });
  return tied;
}

Candidate Refiner::candidate() const
{
  Candidate c = candidateFrom(best_pose_, best_);
  c.covariance = best_cov_;
  return c;
}
}  // namespace

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
