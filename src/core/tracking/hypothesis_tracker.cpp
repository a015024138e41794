// The tracker: options, the search box of a hypothesis, one update of every hypothesis (a miss
// here; a fix in hypothesis_tracker_fix.cpp), pruning and the publishing rule.
#include "fdml_localization/core/tracking/hypothesis_tracker.h"

#include "fdml_localization/core/localization/ranking.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace fdml_localization
{
namespace core
{
namespace
{
/// The smallest box of a hypothesis whose last fix only just reached k', in units of
/// box_min_xy ...
constexpr double kDoubtfulBoxXy = 2.0;
/// ... and of box_min_theta (HypothesisTracker::boxOf()).
constexpr double kDoubtfulBoxTheta = 3.0;

std::string joined(const std::vector<std::string>& errors)
{
  std::string text;
  for (const std::string& error : errors)
  {
    text += (text.empty() ? "" : "; ") + error;
  }
  return text;
}
}  // namespace

HypothesisTracker::HypothesisTracker(std::shared_ptr<const MapRayCaster> map, const TrackerOptions& options)
  : map_(std::move(map)), options_(options)
{
  const std::vector<std::string> errors = validate(options_);
  if (!errors.empty())
  {
    throw std::invalid_argument("tracker options: " + joined(errors));
  }
  if (!map_)
  {
    throw std::invalid_argument("tracker: no map");
  }
  occupancy_ = BoxOccupancy(*map_, options_.cell_xy);
}

int HypothesisTracker::minConsensus(int k) const
{
  const int wanted = static_cast<int>(std::ceil(options_.min_consensus_fraction * k - 1e-9));
  return std::min(k, std::max(3, wanted));
}

LocalSolveSettings HypothesisTracker::solveSettings(int k) const
{
  LocalSolveSettings s;
  s.min_consensus = minConsensus(k);
  s.cell_xy = options_.cell_xy;
  s.cell_theta = options_.cell_theta;
  s.agreement_tolerance = options_.agreement_tolerance;
  s.range_tolerance = options_.range_tolerance;
  s.max_seeds = options_.max_seeds;
  s.direction_group = options_.direction_group;
  return s;
}

PoseBox HypothesisTracker::boxOf(const Hypothesis& h, const Pose2& reference) const
{
  const Pose2 p = compose(h.map_to_odom, reference);
  const TrackerOptions& o = options_;
  // A last fix that only just reached k' may be a place alike beside the truth (a heading a few
  // degrees off explaining people as walls at a slant, precise from them): the box then reaches
  // at least kDoubtfulBoxXy and kDoubtfulBoxTheta times the smallest, where a fix explaining more
  // readings shows it.
  const int k = static_cast<int>(h.last_fix.inlier_mask.size());
  const bool doubtful = h.fixes > 0 && netConsensus(h.last_fix) <= minConsensus(k);
  const double xy =
      std::min(o.box_max_xy, std::max({ positionSigma3(h.covariance),
                                        o.box_min_xy + 3.0 * (o.odom_alpha3 * h.travelled + o.odom_alpha4 * h.turned),
                                        doubtful ? kDoubtfulBoxXy * o.box_min_xy : 0.0 }));
  const double theta = std::min(
      o.box_max_theta, std::max({ headingSigma3(h.covariance),
                                  o.box_min_theta + 3.0 * (o.odom_alpha1 * h.turned + o.odom_alpha2 * h.travelled),
                                  doubtful ? kDoubtfulBoxTheta * o.box_min_theta : 0.0 }));
  return PoseBox{ p.x - xy, p.x + xy, p.y - xy, p.y + xy, p.theta - theta, p.theta + theta };
}

void HypothesisTracker::accumulateMotion(const Pose2& reference)
{
  if (have_reference_)
  {
    const Pose2 d = between(last_reference_, reference);
    const OdometryNoise noise{ options_.odom_alpha1, options_.odom_alpha2, options_.odom_alpha3, options_.odom_alpha4 };
    for (Hypothesis& h : hypotheses_)
    {
      h.travelled += std::hypot(d.x, d.y);
      h.turned += std::abs(d.theta);
      const Pose2 base = compose(h.map_to_odom, last_reference_);
      h.covariance = predictCovariance(h.covariance, base, d, noise);
    }
  }
  last_reference_ = reference;
  have_reference_ = true;
}

bool HypothesisTracker::samePlace(const Pose2& a, const Pose2& b) const
{
  return (a.position() - b.position()).norm() <= options_.merge_distance &&
         std::abs(angleDiff(a.theta, b.theta)) <= options_.merge_angle;
}

UpdateReport HypothesisTracker::update(const std::vector<Reading>& readings, const Pose2& reference)
{
  if (!replaying_)
  {
    history_.push_back(TrackerBatch{ readings, reference });
    while (history_.size() > static_cast<std::size_t>(options_.history_batches + 1 + kMaxCatchUp))
    {
      history_.pop_front();
    }
  }
  UpdateReport report;
  const int k = static_cast<int>(readings.size());
  const LocalSolveSettings settings = solveSettings(k);
  report.min_consensus = settings.min_consensus;
  accumulateMotion(reference);
  for (Hypothesis& h : hypotheses_)
  {
    const bool fixed = updateOne(h, readings, reference, settings, report);
    ++(fixed ? report.fixed : report.missed);
  }
  failed_updates_ = report.fixed > 0 ? 0 : failed_updates_ + 1;
  report.dropped = prune();
  return report;
}

bool HypothesisTracker::updateOne(Hypothesis& h, const std::vector<Reading>& readings, const Pose2& reference,
                                  const LocalSolveSettings& settings, UpdateReport& report)
{
  const double k = static_cast<double>(readings.size());
  const PoseBox box = boxOf(h, reference);
  const Pose2 predicted = compose(h.map_to_odom, reference);
  // The prediction, no more certain than the smallest box, is the polish's prior.
  LocalSolveSettings local = settings;
  local.prior = PosePrior{ predicted, informationOf(h.covariance + leastCovariance()) };
  const LocalSolveOutcome found = localSolve(*map_, occupancy_, readings, box, local);
  report.best_possible = std::max(report.best_possible, found.best_possible);
  report.truncated = report.truncated || found.truncated;
  if (found.fixes.empty())
  {
    // A miss earns what the best pose refined in the box explains (below k'), or the prediction
    // when the search pruned the whole box: people hiding readings of the true place must not
    // hand its support to a place alike that explains one reading more. Readings only hidden
    // let the hypothesis coast on odometry; contradicted ones do not.
    ++h.misses;
    h.conflicted = found.least_contradicted >= options_.conflict_readings;
    h.support = options_.support_decay * h.support + std::max(0, found.best_consensus) / k;
    return false;
  }
  takeFix(h, readings, reference, box, found);
  return true;
}

bool HypothesisTracker::withinMargins(const Eigen::Matrix3d& covariance) const
{
  return positionSigma3(covariance) <= options_.publish_max_xy &&
         headingSigma3(covariance) <= options_.publish_max_theta;
}

int HypothesisTracker::prune()
{
  const std::size_t before = hypotheses_.size();
  hypotheses_.erase(std::remove_if(hypotheses_.begin(), hypotheses_.end(),
                                   [&](const Hypothesis& h) { return h.misses >= options_.max_misses; }),
                    hypotheses_.end());
  std::stable_sort(hypotheses_.begin(), hypotheses_.end(), [](const Hypothesis& a, const Hypothesis& b) {
    return a.support != b.support ? a.support > b.support : a.id < b.id;
  });
  std::vector<Hypothesis> kept;
  for (Hypothesis& h : hypotheses_)
  {
    const Pose2 pose = compose(h.map_to_odom, last_reference_);
    const bool duplicate = std::any_of(kept.begin(), kept.end(), [&](const Hypothesis& other) {
      return samePlace(compose(other.map_to_odom, last_reference_), pose);
    });
    if (!duplicate && static_cast<int>(kept.size()) < options_.max_hypotheses)
    {
      kept.push_back(std::move(h));
    }
  }
  hypotheses_ = std::move(kept);
  return static_cast<int>(before - hypotheses_.size());
}

void HypothesisTracker::clear()
{
  hypotheses_.clear();
  history_.clear();
  failed_updates_ = 0;
}

void HypothesisTracker::restore(std::vector<Hypothesis> hypotheses)
{
  hypotheses_ = std::move(hypotheses);
  for (const Hypothesis& h : hypotheses_)
  {
    next_id_ = std::max(next_id_, h.id + 1);
  }
}

const Hypothesis* HypothesisTracker::supportedUnconfirmed() const
{
  if (hypotheses_.empty())
  {
    return nullptr;
  }
  const Hypothesis& best = hypotheses_.front();
  const double second = hypotheses_.size() > 1 ? hypotheses_[1].support : 0.0;
  const bool clear = best.misses <= options_.tolerated_misses && !best.conflicted &&
                     best.support >= options_.min_support && best.support - second >= options_.support_margin &&
                     withinMargins(best.covariance);
  return clear ? &best : nullptr;
}

const Hypothesis* HypothesisTracker::clearlySupported() const
{
  const Hypothesis* best = supportedUnconfirmed();
  return best && best->confirmations >= options_.confirm_searches ? best : nullptr;
}

bool HypothesisTracker::awaitingConfirmation() const
{
  const Hypothesis* best = supportedUnconfirmed();
  return best && best->confirmations < options_.confirm_searches;
}

TrackState HypothesisTracker::state() const
{
  if (hypotheses_.empty())
  {
    return TrackState::Empty;
  }
  if (clearlySupported())
  {
    return TrackState::Tracking;
  }
  // A hypothesis coasting through misses without a conflict (readings hidden by people, a
  // stretch the readings barely constrain) is not lost.
  const bool coasting = std::any_of(hypotheses_.begin(), hypotheses_.end(), [&](const Hypothesis& h) {
    return h.fixes > 0 && !h.conflicted && h.misses <= options_.tolerated_misses;
  });
  return failed_updates_ >= options_.lost_updates && !coasting ? TrackState::Lost : TrackState::Ambiguous;
}

}  // namespace core
}  // namespace fdml_localization
