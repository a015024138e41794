// How a fix changes a hypothesis (HypothesisTracker::takeFix()): which of the box's fixes carries
// it, the covariance it is fused with (its own, its one-direction loss, the gate against the
// prediction), whether it may narrow the hypothesis, and whether the fused pose still explains
// what the fix explains.
#include "fdml_localization/core/tracking/hypothesis_tracker.h"

#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <boost/math/distributions/chi_squared.hpp>

#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{

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
}  // namespace

void HypothesisTracker::takeFix(Hypothesis& h, const std::vector<Reading>& readings, const Pose2& reference,
                                const PoseBox& box, const LocalSolveOutcome& found)
{
  const Pose2 predicted = compose(h.map_to_odom, reference);
  const std::size_t chosen = chooseFix(found.fixes, predicted);
  const Candidate& fix = found.fixes[chosen];
  const FusedPose fused = fusePose(predicted, h.covariance, fix.pose, fixNoise(h, predicted, found, chosen));
  h.map_to_odom = compose(fused.pose, inverse(reference));
  h.covariance = onlyPlace(h.covariance, box, fused, readings, fix) ? fused.covariance : h.covariance;
  // The pose must explain what its fix explains. Where it leaves readings the fix explains longer
  // than the map allows, the prediction held it where the readings refute it (a heading 5.8 deg
  // off, precise from fixes one sensor alone turned, its front ray hitting the hall's wall 2.3 m
  // short of every front reading that passed the door): it is wrong, withheld, and no surer
  // than its distance from the fix.
  const bool refuted =
      evaluatePose(*map_, fused.pose, readings, options_.agreement_tolerance).contradicted - fix.contradicted >=
      options_.conflict_readings;
  if (refuted)
  {
    const Eigen::Vector3d d = poseDifference(fix.pose, fused.pose);
    h.covariance += d * d.transpose();
  }
  h.travelled = 0.0;
  h.turned = 0.0;
  h.misses = 0;
  // A fix that leaves readings longer than the map allows is in conflict too: after a kidnap,
  // the old place along a corridor explained 8 of 10 new readings and contradicted 2, and was
  // published again for 0.4 s.
  h.conflicted = fix.contradicted >= options_.conflict_readings || refuted;
  ++h.fixes;
  h.support = options_.support_decay * h.support + static_cast<double>(netConsensus(fix)) / readings.size();
  h.last_fix = fix;
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

}  // namespace core
}  // namespace fdml_localization
