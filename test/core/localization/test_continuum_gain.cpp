// gainAlongContinuum() (continuum_gain.cpp) and settleAlongContinua() through it: a candidate on a
// corridor's continuum, exact on all readings but one, moved to the stretch where a side sensor
// passing a door frame explains that one too; checked against the stretch the geometry gives.
#include "localizer_test_utils.h"
#include "verification_trials.h"

#include "fdml_localization/core/localization/certificate.h"
#include "fdml_localization/core/localization/continuum_gain.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <gtest/gtest.h>

#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
/// A 20 x 1.2 m corridor with a door 0.9 m wide and 0.6 m deep in its south wall at x = 10 m.
std::shared_ptr<const MapRayCaster> corridorWithDoor()
{
  return std::make_shared<const MapRayCaster>(
      PolygonMap::fromRings({ { Vec2(0.0, 0.0), Vec2(10.0, 0.0), Vec2(10.0, -0.6), Vec2(10.9, -0.6), Vec2(10.9, 0.0),
                                Vec2(20.0, 0.0), Vec2(20.0, 1.2), Vec2(0.0, 1.2) } }));
}

/// The four-sensor robot (front, left, back, right, 0.15 m) driving east 1 cm per reading from
/// @p truth, 24 readings of max range 3 m: the front and back see no wall, the right sensor
/// (readings 3, 7, ..., 23) passes the door's west post between readings 19 and 23 when
/// truth.x is in (9.77, 9.81) m.
std::vector<Reading> drivePastTheDoor(const MapRayCaster& map, const Pose2& truth)
{
  std::mt19937_64 rng(0);
  std::vector<Reading> readings =
      test::exactReadings(map, truth, verification::trialOffsets(verification::kDriving, 24, rng));
  for (Reading& r : readings)
  {
    r.max_range = 3.0;
    r.range = r.range > r.max_range ? kInf : r.range;
  }
  return readings;
}

TEST(GainAlongContinuum, FindsTheStretchWhereASideSensorPassesTheDoorPost)
{
  const auto map = corridorWithDoor();
  const Pose2 truth(9.80, 0.6, 0.0);
  const std::vector<Reading> readings = drivePastTheDoor(*map, truth);
  ASSERT_EQ(consensusWithin(*map, truth, readings, 0.01), 24);
  ASSERT_NEAR(readings[23].range, 1.05, 1e-9);  // into the door
  ASSERT_NEAR(readings[19].range, 0.45, 1e-9);  // the wall before it

  // 10 cm back along the corridor every reading agrees exactly except the one into the door.
  Candidate start = verifiedCandidate(*map, Pose2(9.70, 0.6, 0.0), readings, 0.05);
  ASSERT_EQ(start.inliers, 23);
  ASSERT_LT(start.rms_residual, kExactRms);

  const Candidate gained =
      gainAlongContinuum(*map, readings, test::continuumSettings(), start, Eigen::Vector2d::UnitX(), 4.0, 0.11);
  EXPECT_EQ(gained.inliers, 24);
  EXPECT_EQ(gained.contradicted, 0);
  // Within the stretch the geometry allows, its middle (9.79 m) by construction.
  EXPECT_GT(gained.pose.x, 9.77);
  EXPECT_LT(gained.pose.x, 9.81);
  EXPECT_NEAR(gained.pose.y, 0.6, 1e-6);
  EXPECT_NEAR(gained.pose.theta, 0.0, 1e-6);
  EXPECT_GT(gained.covariance.trace(), 0.0);

  // Nothing to gain from the truth's stretch itself: the candidate comes back unchanged.
  const Candidate exact = verifiedCandidate(*map, truth, readings, 0.05);
  const Candidate same =
      gainAlongContinuum(*map, readings, test::continuumSettings(), exact, Eigen::Vector2d::UnitX(), 0.5, 0.5);
  EXPECT_EQ(test::positionError(same.pose, truth), 0.0);
}

TEST(SettleAlongContinua, MovesAnExactCandidateToWhereItExplainsMoreReadings)
{
  const auto map = corridorWithDoor();
  const Pose2 truth(9.80, 0.6, 0.0);
  const std::vector<Reading> readings = drivePastTheDoor(*map, truth);
  Candidate candidate = verifiedCandidate(*map, Pose2(9.70, 0.6, 0.0), readings, 0.05);
  ensureCovariance(*map, readings, 0.01, candidate);
  ASSERT_EQ(netConsensus(candidate), 22);  // the reading into the door contradicts it

  settleAlongContinua(*map, readings, test::continuumSettings(), candidate);
  EXPECT_EQ(netConsensus(candidate), 24);
  EXPECT_GT(candidate.pose.x, 9.77);
  EXPECT_LT(candidate.pose.x, 9.81);
  // Along the corridor only the post fixes the pose: the covariance still says it is loose.
  EXPECT_GT(std::sqrt(candidate.covariance(0, 0)), 0.01);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
