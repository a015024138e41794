// Tests of the tracker's Kalman steps (pose_filter.h) against closed forms.
#include "fdml_localization/core/tracking/pose_filter.h"

#include <Eigen/LU>
#include <gtest/gtest.h>

#include <cmath>

namespace core = fdml_localization::core;

TEST(PoseFilter, DrivingSpreadsTheHeadingIntoThePosition)
{
  // Heading known to 0.05 rad, position exact; 2 m straight ahead along +x with no odometry
  // noise: the lateral position inherits 2 m x the heading's uncertainty, fully correlated.
  const Eigen::Matrix3d prior = Eigen::Vector3d(0.0, 0.0, 0.05 * 0.05).asDiagonal();
  const core::OdometryNoise none{ 0.0, 0.0, 0.0, 0.0 };
  const Eigen::Matrix3d p =
      core::predictCovariance(prior, core::Pose2(1.0, 2.0, 0.0), core::Pose2(2.0, 0.0, 0.0), none);
  EXPECT_NEAR(p(1, 1), 4.0 * 0.05 * 0.05, 1e-12);
  EXPECT_NEAR(p(1, 2), 2.0 * 0.05 * 0.05, 1e-12);
  EXPECT_NEAR(p(0, 0), 0.0, 1e-12);
  // The odometry noise adds (alpha3 |trans|)^2 in x and y, (alpha2 |trans|)^2 in theta.
  const core::OdometryNoise noise{ 0.1, 0.2, 0.3, 0.4 };
  const Eigen::Matrix3d q =
      core::predictCovariance(Eigen::Matrix3d::Zero(), core::Pose2(), core::Pose2(2.0, 0.0, 0.5), noise);
  EXPECT_NEAR(q(0, 0), std::pow(0.3 * 2.0 + 0.4 * 0.5, 2), 1e-12);
  EXPECT_NEAR(q(2, 2), std::pow(0.1 * 0.5 + 0.2 * 2.0, 2), 1e-12);
}

TEST(PoseFilter, ALateralFixCorrectsTheCorrelatedHeading)
{
  // After the drive above the prediction is 0.02 rad off in heading and so 4 cm off sideways;
  // a fix that sees only the lateral position (a corridor: x and theta loose) brings both back.
  const Eigen::Matrix3d prior = Eigen::Vector3d(1e-6, 0.0, 0.05 * 0.05).asDiagonal();
  const core::OdometryNoise none{ 0.0, 0.0, 0.0, 0.0 };
  const Eigen::Matrix3d p = core::predictCovariance(prior, core::Pose2(), core::Pose2(2.0, 0.0, 0.0), none) +
                            Eigen::Matrix3d(Eigen::Vector3d(1e-6, 1e-6, 1e-6).asDiagonal());
  const core::Pose2 predicted(2.0, 0.04, 0.02);
  const core::Pose2 truth(2.0, 0.0, 0.0);
  const Eigen::Matrix3d noise = Eigen::Vector3d(4.0, 0.005 * 0.005, 1.0).asDiagonal();
  const core::FusedPose fused = core::fusePose(predicted, p, core::Pose2(2.0, 0.0, 0.3), noise);
  EXPECT_NEAR(fused.pose.y, truth.y, 0.01);
  EXPECT_NEAR(fused.pose.theta, truth.theta, 0.006);
  // The posterior is the information-form one, (P^-1 + R^-1)^-1.
  const Eigen::Matrix3d expected = (p.inverse() + noise.inverse()).inverse();
  EXPECT_LT((fused.covariance - expected).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(core::headingSigma3(fused.covariance), core::headingSigma3(p) / 3.0);
}

TEST(PoseFilter, AFixWithoutCovarianceIsTakenAsItIs)
{
  const Eigen::Matrix3d prior = Eigen::Vector3d(0.01, 0.01, 0.01).asDiagonal();
  const core::FusedPose fused =
      core::fusePose(core::Pose2(0.0, 0.0, 0.0), prior, core::Pose2(1.0, 2.0, 0.5), Eigen::Matrix3d::Zero());
  EXPECT_DOUBLE_EQ(fused.pose.x, 1.0);
  EXPECT_DOUBLE_EQ(fused.pose.theta, 0.5);
  EXPECT_EQ(fused.covariance, prior);
  EXPECT_NEAR(core::positionSigma3(Eigen::Vector3d(0.04, 0.01, 0.0).asDiagonal()), 0.6, 1e-12);
}

TEST(PoseFilter, SquaredMahalanobisWrapsTheHeading)
{
  // 3 cm in x at 1 cm, 0.02 rad across +-pi at 0.01 rad: 9 + 4.
  const Eigen::Matrix3d covariance = Eigen::Vector3d(1e-4, 1e-4, 1e-4).asDiagonal();
  const core::Pose2 a(1.03, 2.0, core::kPi - 0.01);
  const core::Pose2 b(1.0, 2.0, -core::kPi + 0.01);
  EXPECT_NEAR(core::squaredMahalanobis(a, b, covariance), 13.0, 1e-9);
  EXPECT_TRUE(std::isinf(core::squaredMahalanobis(a, b, Eigen::Matrix3d::Zero())));
}
