#include "fdml_localization/core/tracking/hypothesis_tracker.h"

#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <boost/math/distributions/chi_squared.hpp>

#include <algorithm>
#include <cmath>
#include <iterator>
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

/// @p m reduced to at most @p bound in every direction: its eigenvalues relative to @p bound
/// (whitened by bound's Cholesky factor) clamped to 1. @p m when @p bound is not positive definite.
Eigen::Matrix3d cappedBy(const Eigen::Matrix3d& m, const Eigen::Matrix3d& bound)
{
  const Eigen::LLT<Eigen::Matrix3d> llt(bound);
  if (llt.info() != Eigen::Success)
  {
    return m;
  }
  const Eigen::Matrix3d l = llt.matrixL();
  const Eigen::Matrix3d l_inv = l.inverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(l_inv * m * l_inv.transpose());
  const Eigen::Vector3d kept = eigen.eigenvalues().cwiseMax(0.0).cwiseMin(1.0);
  return l * eigen.eigenvectors() * kept.asDiagonal() * eigen.eigenvectors().transpose() * l.transpose();
}

/// True when the innovation @p d (fix - prediction) [m, m, rad] fails the gate in the directions
/// where the fix's precision comes from one direction's readings alone: those where @p loss
/// exceeds @p covariance (the prediction's plus the fix's own), whitened by it. There the
/// prediction is the fix's only witness, and its squared Mahalanobis distance over those r
/// directions must stay within the chi-square quantile of r degrees of freedom at the
/// probability @p gate has for 3 (6.63 for one direction at the 99 % of 11.34).
bool disagreesAlone(const Eigen::Vector3d& d, const Eigen::Matrix3d& covariance, const Eigen::Matrix3d& loss,
                    double gate)
{
  const Eigen::LLT<Eigen::Matrix3d> llt(covariance);
  if (llt.info() != Eigen::Success || !d.allFinite() || !loss.allFinite())
  {
    return false;
  }
  const Eigen::Matrix3d l_inv = Eigen::Matrix3d(llt.matrixL()).inverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(l_inv * loss * l_inv.transpose());
  const Eigen::Vector3d w = l_inv * d;
  double m2 = 0.0;
  int r = 0;
  for (int j = 0; j < 3; ++j)
  {
    if (eigen.eigenvalues()(j) > 1.0)
    {
      m2 += std::pow(eigen.eigenvectors().col(j).dot(w), 2);
      ++r;
    }
  }
  const double p = boost::math::cdf(boost::math::chi_squared(3.0), gate);
  return r > 0 && p < 1.0 - 1e-12 && m2 > boost::math::quantile(boost::math::chi_squared(r), p);
}

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
    // A miss earns what the best pose refined in the box explains (below k'; 0 when the search
    // pruned the whole box): a solver's near miss costs less than an empty box. Readings only
    // hidden (by people) let the hypothesis coast on odometry; contradicted ones do not.
    ++h.misses;
    h.conflicted = found.least_contradicted >= options_.conflict_readings;
    h.support = options_.support_decay * h.support + std::max(0, found.best_consensus) / k;
    return false;
  }
  const std::size_t chosen = chooseFix(found.fixes, predicted);
  const Candidate& fix = found.fixes[chosen];
  const FusedPose fused = fusePose(predicted, h.covariance, fix.pose, fixNoise(h, predicted, found, chosen));
  h.map_to_odom = compose(fused.pose, inverse(reference));
  h.covariance = onlyPlace(h.covariance, box, fused, readings, fix) ? fused.covariance : h.covariance;
  h.travelled = 0.0;
  h.turned = 0.0;
  h.misses = 0;
  // A fix that leaves readings longer than the map allows is in conflict too: after a kidnap,
  // the old place along a corridor explained 8 of 10 new readings and contradicted 2, and was
  // published again for 0.4 s.
  h.conflicted = fix.contradicted >= options_.conflict_readings;
  ++h.fixes;
  h.support = options_.support_decay * h.support + static_cast<double>(netConsensus(fix)) / k;
  h.last_fix = fix;
  return true;
}

Eigen::Matrix3d HypothesisTracker::fixNoise(const Hypothesis& h, const Pose2& predicted, const LocalSolveOutcome& found,
                                            std::size_t i) const
{
  // A fix counts as one of k / stride overlapping batches, and with what it loses without any
  // one direction (a person may shorten every reading of one sensor alike); how far a prediction
  // vouches for it or contradicts it: TrackerOptions::fix_gate.
  const Candidate& fix = found.fixes[i];
  const Eigen::Matrix3d own = options_.fix_covariance_scale * fix.covariance;
  const Eigen::Matrix3d loss = options_.fix_covariance_scale * found.direction_loss[i];
  if (options_.fix_gate <= 0.0)
  {
    return own + loss;
  }
  const Eigen::Vector3d d = poseDifference(fix.pose, predicted);
  if (squaredMahalanobis(fix.pose, predicted, h.covariance + own) > options_.fix_gate ||
      (withinMargins(h.covariance) && disagreesAlone(d, h.covariance + own, loss, options_.fix_gate)))
  {
    // Disagreeing: the fix or the prediction is wrong (a person read as a wall at a slant, an
    // alike place in the box). It counts only up to its disagreement.
    return own + loss + d * d.transpose();
  }
  // Agreeing with a prediction as precise as a published pose: what one direction alone fixes
  // is checked only to the prediction's precision, and counts no more than it.
  return withinMargins(h.covariance) ? own + cappedBy(loss, h.covariance) : own + loss;
}

bool HypothesisTracker::onlyPlace(const Eigen::Matrix3d& predicted, const PoseBox& box, const FusedPose& fused,
                                  const std::vector<Reading>& readings, const Candidate& fix) const
{
  // The box is capped (box_max_*): where the prediction's 3 sigma reaches beyond it, the local
  // solve saw only part of where the robot may be. A fix that would bring the hypothesis within
  // its box there (a door seen along a corridor the drift has made uncertain by metres) may be
  // one of several alike places: it narrows the hypothesis only once no other place of the
  // prediction's 3-sigma region may explain as many readings.
  const Eigen::Vector3d sigma3 = 3.0 * predicted.diagonal().cwiseMax(0.0).cwiseSqrt();
  const double half_xy = 0.5 * (box.x1 - box.x0);
  const double half_theta = 0.5 * (box.t1 - box.t0);
  const bool covered = sigma3.x() <= half_xy && sigma3.y() <= half_xy && sigma3.z() <= half_theta;
  const double fused_xy = positionSigma3(fused.covariance);
  const double fused_theta = headingSigma3(fused.covariance);
  const bool narrows = fused_xy <= half_xy && fused_theta <= half_theta;
  if (covered || !narrows || !sigma3.allFinite())
  {
    return true;
  }
  const Pose2 p = box.centre();
  const double t = std::min(kPi, sigma3.z());
  const PoseBox region{
    p.x - sigma3.x(), p.x + sigma3.x(), p.y - sigma3.y(), p.y + sigma3.y(), p.theta - t, p.theta + t
  };
  return onlyPlaceInRegion(*map_, occupancy_, readings, region, fused.pose, std::max(1, netConsensus(fix)), fused_xy,
                           fused_theta, solveSettings(static_cast<int>(readings.size())));
}

bool HypothesisTracker::withinMargins(const Eigen::Matrix3d& covariance) const
{
  return positionSigma3(covariance) <= options_.publish_max_xy &&
         headingSigma3(covariance) <= options_.publish_max_theta;
}

std::size_t HypothesisTracker::chooseFix(const std::vector<Candidate>& fixes, const Pose2& predicted) const
{
  // Among the fixes tied with the best on net consensus, the one nearest the prediction (the box
  // is the hypothesis's uncertainty: new places come from global solves only).
  const int best = netConsensus(fixes.front());
  std::size_t chosen = 0;
  for (std::size_t i = 1; i < fixes.size() && netConsensus(fixes[i]) == best; ++i)
  {
    if ((fixes[i].pose.position() - predicted.position()).norm() <
        (fixes[chosen].pose.position() - predicted.position()).norm())
    {
      chosen = i;
    }
  }
  return chosen;
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
