// oneDirectionLostCovariance() (robust_search.h): what a fix's covariance gains when the readings
// of one direction (one sensor) are all wrong, checked on rooms and corridors whose geometry says
// which sensors fix which direction.
#include "fdml_localization/core/localization/robust_search.h"

#include "localizer_test_utils.h"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <memory>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace
{
std::shared_ptr<const MapRayCaster> corridorOf(double length)
{
  return std::make_shared<const MapRayCaster>(
      PolygonMap::fromRings({ { { 0, 0 }, { length, 0 }, { length, 2 }, { 0, 2 } } }));
}

/// Four sensors (front, left, back, right) 0.15 m from the centre, twice each.
std::vector<Pose2> fourSensorsTwice()
{
  std::vector<Pose2> offsets;
  for (int i = 0; i < 8; ++i)
  {
    const double a = (i % 4) * 0.5 * kPi;
    offsets.emplace_back(0.15 * std::cos(a), 0.15 * std::sin(a), wrapAngle(a));
  }
  return offsets;
}

TEST(OneDirectionLost, AddsOnlyWhereOneSensorAloneFixesTheDirection)
{
  const std::vector<bool> all(8, true);
  // A 5 m x 2 m room, the robot turned 0.3 rad: each of x, y fixed by two opposite sensors.
  const auto room = corridorOf(5.0);
  const Pose2 in_room(2.4, 1.1, 0.3);
  const std::vector<Reading> room_readings = test::exactReadings(*room, in_room, fourSensorsTwice());
  const Eigen::Matrix3d base = polishPose(*room, in_room, room_readings, all, 0.0, 0, 0.01).covariance;
  const Eigen::Matrix3d added = oneDirectionLostCovariance(*room, in_room, room_readings, all, 0.01, 0.25);
  // Small: a few mm (x and the heading need front and back together at this angle).
  EXPECT_LT(added.trace(), 1e-3) << added << "\nbase\n" << base;
  // A 20 m corridor, the back sensor seeing nothing within 8 m: only the front one fixes x.
  const auto corridor = corridorOf(20.0);
  const Pose2 in_corridor(15.0, 1.0, 0.0);
  std::vector<Reading> readings = test::exactReadings(*corridor, in_corridor, fourSensorsTwice());
  for (Reading& r : readings)
  {
    r.max_range = 8.0;
    r.range = r.range > 8.0 ? kInf : r.range;
  }
  const Eigen::Matrix3d lost = oneDirectionLostCovariance(*corridor, in_corridor, readings, all, 0.01, 0.25);
  EXPECT_GT(lost(0, 0), 1.0) << lost;   // x: no better than the prior (the map's size) without it
  EXPECT_LT(lost(1, 1), 1e-6) << lost;  // y: fixed by left and right alike
  // A group angle of 0 still groups a sensor's two readings (one mounting heading).
  EXPECT_GT(oneDirectionLostCovariance(*corridor, in_corridor, readings, all, 0.01, 0.0)(0, 0), 1.0);
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(lost);
  EXPECT_GE(eigen.eigenvalues().minCoeff(), -1e-12);  // positive semi-definite
}

TEST(OneDirectionLost, ASensorWithReadingsThatDisagreeFixesNoDirectionAlone)
{
  // A 100 m corridor 2 m wide, the robot 0.3 m from its left wall: the back sensor alone fixes
  // x (the end wall 4.85 m away), the side sensors fix y, and the front one, turned 0.1 rad,
  // hits the left wall 3 m ahead at a slant: it alone fixes the heading (seed 3 of the patrol
  // replay: a person in front read as a wall at a slant by one front reading, the other front
  // reading off). Losing the back sensor leaves the larger covariance (x: the map's extent).
  const auto corridor = corridorOf(100.0);
  const Pose2 at(5.0, 1.7, 0.0);
  std::vector<Pose2> offsets;
  for (int twice = 0; twice < 2; ++twice)
  {
    offsets.insert(offsets.end(), { Pose2(0.15, 0.0, 0.1), Pose2(0.0, 0.15, 0.5 * kPi), Pose2(-0.15, 0.0, kPi),
                                    Pose2(0.0, -0.15, -0.5 * kPi) });
  }
  const std::vector<Reading> clean = test::exactReadings(*corridor, at, offsets);
  const Eigen::Matrix3d plain =
      oneDirectionLostCovariance(*corridor, at, clean, std::vector<bool>(8, true), 0.01, 0.25);
  EXPECT_GT(plain(0, 0), 100.0) << plain;  // x: only the back sensor's
  EXPECT_LT(plain(2, 2), 1e-6) << plain;   // the heading, fixed by a sensor that agrees: kept
  // A third front reading 1 m short of the wall (a person), not an inlier: the front sensor's
  // heading is counted as lost too.
  std::vector<Reading> spoilt = clean;
  spoilt.push_back(clean.front());
  spoilt.back().range -= 1.0;
  std::vector<bool> inliers(9, true);
  inliers.back() = false;
  const Eigen::Matrix3d lost = oneDirectionLostCovariance(*corridor, at, spoilt, inliers, 0.01, 0.25);
  EXPECT_GT(lost(0, 0), 100.0) << lost;
  EXPECT_GT(lost(2, 2), 1.0) << lost;   // no better than any heading
  EXPECT_LT(lost(1, 1), 1e-6) << lost;  // y: fixed by left and right alike
  // A no-return reading is no disagreement.
  spoilt.back().range = kInf;
  spoilt.back().max_range = 8.0;
  EXPECT_LT(oneDirectionLostCovariance(*corridor, at, spoilt, inliers, 0.01, 0.25)(2, 2), 1e-6);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
