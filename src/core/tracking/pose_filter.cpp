#include "fdml_localization/core/tracking/pose_filter.h"

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace core
{
namespace
{
/// True when @p covariance is finite and positive definite by its factorisation @p ldlt, with a
/// positive diagonal: a usable covariance (fusePose(), informationOf()).
bool positiveDefinite(const Eigen::Matrix3d& covariance, const Eigen::LDLT<Eigen::Matrix3d>& ldlt)
{
  return covariance.allFinite() && ldlt.info() == Eigen::Success && ldlt.isPositive() &&
         covariance.diagonal().minCoeff() > 0.0;
}
}  // namespace

Eigen::Matrix3d predictCovariance(const Eigen::Matrix3d& covariance, const Pose2& pose, const Pose2& step,
                                  const OdometryNoise& noise)
{
  // q' = q (+) d: dq'/dq = [1 0 -s dx - c dy; 0 1 c dx - s dy; 0 0 1].
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();
  jacobian(0, 2) = -s * step.x - c * step.y;
  jacobian(1, 2) = c * step.x - s * step.y;
  const double trans = std::hypot(step.x, step.y);
  const double rot = std::abs(step.theta);
  const double sigma_xy = noise.alpha3 * trans + noise.alpha4 * rot;
  const double sigma_theta = noise.alpha1 * rot + noise.alpha2 * trans;
  const Eigen::Vector3d q(sigma_xy * sigma_xy, sigma_xy * sigma_xy, sigma_theta * sigma_theta);
  const Eigen::Matrix3d predicted = jacobian * covariance * jacobian.transpose();
  return 0.5 * (predicted + predicted.transpose()) + Eigen::Matrix3d(q.asDiagonal());
}

FusedPose fusePose(const Pose2& predicted, const Eigen::Matrix3d& prior, const Pose2& measured,
                   const Eigen::Matrix3d& noise)
{
  FusedPose fused{ measured, prior };
  const Eigen::Matrix3d sum = prior + noise;
  if (!positiveDefinite(noise, Eigen::LDLT<Eigen::Matrix3d>(noise)) || !prior.allFinite() ||
      std::abs(sum.determinant()) < 1e-30)
  {
    return fused;
  }
  const Eigen::Matrix3d gain = prior * sum.inverse();
  const Eigen::Vector3d step = gain * poseDifference(measured, predicted);
  fused.pose = Pose2(predicted.x + step.x(), predicted.y + step.y(), wrapAngle(predicted.theta + step.z()));
  // Joseph form: stays symmetric and positive semi-definite.
  const Eigen::Matrix3d keep = Eigen::Matrix3d::Identity() - gain;
  const Eigen::Matrix3d covariance = keep * prior * keep.transpose() + gain * noise * gain.transpose();
  fused.covariance = 0.5 * (covariance + covariance.transpose());
  return fused;
}

Eigen::Matrix3d informationOf(const Eigen::Matrix3d& covariance)
{
  const Eigen::LDLT<Eigen::Matrix3d> ldlt(covariance);
  if (!positiveDefinite(covariance, ldlt))
  {
    return Eigen::Matrix3d::Zero();
  }
  const Eigen::Matrix3d information = ldlt.solve(Eigen::Matrix3d::Identity());
  return information.allFinite() ? Eigen::Matrix3d(0.5 * (information + information.transpose())) :
                                   Eigen::Matrix3d::Zero();
}

double squaredMahalanobis(const Pose2& measured, const Pose2& predicted, const Eigen::Matrix3d& covariance)
{
  const Eigen::Matrix3d information = informationOf(covariance);
  if (information.isZero())
  {
    return std::numeric_limits<double>::infinity();
  }
  const Eigen::Vector3d d = poseDifference(measured, predicted);
  return d.dot(information * d);
}

double positionSigma3(const Eigen::Matrix3d& covariance)
{
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> solver(covariance.topLeftCorner<2, 2>());
  return 3.0 * std::sqrt(std::max(0.0, solver.eigenvalues().maxCoeff()));
}

double headingSigma3(const Eigen::Matrix3d& covariance)
{
  return 3.0 * std::sqrt(std::max(0.0, covariance(2, 2)));
}

}  // namespace core
}  // namespace fdml_localization
