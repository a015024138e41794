/**
 * @file pose_filter.h
 * @brief The tracker's Kalman steps on one hypothesis: the covariance of the base's pose in the
 *        map carried by an odometry step (the heading's uncertainty spreads into the position
 *        along the way, so a later fix of the position also corrects the heading), and a fix
 *        fused with the prediction by both covariances (a direction the readings leave loose
 *        keeps the prediction).
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <Eigen/Core>

namespace fdml_localization
{
namespace core
{
/// Odometry noise per step, AMCL's odom_alpha1..4 meanings: the step adds a standard deviation
/// sigma_theta = alpha1 |rot| + alpha2 |trans| [rad] and sigma_xy = alpha3 |trans| + alpha4 |rot|
/// [m] (in x and in y).
struct OdometryNoise
{
  double alpha1 = 0.2;  ///< [rad/rad]
  double alpha2 = 0.2;  ///< [rad/m]
  double alpha3 = 0.2;  ///< [m/m]
  double alpha4 = 0.2;  ///< [m/rad]
};

/**
 * @brief The covariance of pose (+) @p step given @p covariance of @p pose (map frame, x, y,
 *        theta): J P J^T + Q, J the derivative of the composition by the pose, Q the step's
 *        odometry noise.
 */
Eigen::Matrix3d predictCovariance(const Eigen::Matrix3d& covariance, const Pose2& pose, const Pose2& step,
                                  const OdometryNoise& noise);

/// A fused pose and its covariance.
struct FusedPose
{
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
};

/**
 * @brief One Kalman step: @p predicted (covariance @p prior) corrected by the fix @p measured
 *        (covariance @p noise). A fix without a usable covariance (not finite, not positive
 *        definite) is taken as it is, with the prior's covariance.
 */
FusedPose fusePose(const Pose2& predicted, const Eigen::Matrix3d& prior, const Pose2& measured,
                   const Eigen::Matrix3d& noise);

/// The information (inverse) of @p covariance; zero (no information) when it is not finite or
/// not positive definite.
Eigen::Matrix3d informationOf(const Eigen::Matrix3d& covariance);

/// The squared Mahalanobis distance of @p measured from @p predicted (heading difference
/// wrapped) under @p covariance; +inf when the covariance is not finite or not positive definite.
double squaredMahalanobis(const Pose2& measured, const Pose2& predicted, const Eigen::Matrix3d& covariance);

/// 3 standard deviations of @p covariance along its least certain direction in (x, y) [m].
double positionSigma3(const Eigen::Matrix3d& covariance);
/// 3 standard deviations of the heading [rad].
double headingSigma3(const Eigen::Matrix3d& covariance);

}  // namespace core
}  // namespace fdml_localization
