// region_starts.h: the agreement score with casts cut at d + gate against the same score from
// evaluatePose()'s full casts (rays, cones and no-return readings, poses in and out of free
// space), the one residual rule of every count of agreeing readings, and seed starts moved off
// the walls.
#include "fdml_localization/core/localization/region_starts.h"

#include "fdml_localization/core/localization/certificate.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
/// The score from evaluatePose(): gate^2 per reading that does not agree, r^2 per finite one that does.
double referenceScore(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings, double gate)
{
  const PoseEvaluation e = evaluatePose(map, pose, readings, gate);
  double score = static_cast<double>(readings.size() - static_cast<std::size_t>(e.inliers)) * gate * gate;
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    score += e.inlier_mask[i] && std::isfinite(e.residuals[i]) ? e.residuals[i] * e.residuals[i] : 0.0;
  }
  return score;
}
}  // namespace

TEST(RegionStarts, AgreementScoreEqualsTheFullCastScore)
{
  const auto map = test::loadMap("maps/office.poly");
  std::mt19937_64 rng(16);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const Box2& b = map->map().bounds();
  int agreeing = 0;
  for (int trial = 0; trial < 300; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng);
    std::vector<Pose2> offsets;
    for (int i = 0; i < 8; ++i)
    {
      offsets.emplace_back(0.1 * (unit(rng) - 0.5), 0.1 * (unit(rng) - 0.5), kTwoPi * unit(rng));
    }
    std::vector<Reading> readings = test::exactReadings(*map, truth, offsets);
    const double max_range = trial % 3 == 0 ? 1.0 + 3.0 * unit(rng) : kInf;
    for (Reading& r : readings)
    {
      r.half_angle = trial % 2 == 0 ? 0.2 * unit(rng) : 0.0;
      r.max_range = max_range;
      r.range = r.range > max_range ? kInf : r.range + 0.05 * (unit(rng) - 0.5);
    }
    // Near the truth (partly agreeing) and anywhere in the map's box (walls and outside too).
    const Pose2 near(truth.x + 0.1 * (unit(rng) - 0.5), truth.y + 0.1 * (unit(rng) - 0.5),
                     truth.theta + 0.1 * unit(rng));
    const Pose2 anywhere(b.min.x() + b.size().x() * unit(rng), b.min.y() + b.size().y() * unit(rng),
                         kTwoPi * unit(rng));
    for (const Pose2& pose : { truth, near, anywhere })
    {
      const double gate = 0.03 + 0.3 * unit(rng);
      const double expected = referenceScore(*map, pose, readings, gate);
      ASSERT_NEAR(agreementScore(*map, pose, readings, gate), expected, 1e-12) << "trial " << trial;
      agreeing += expected < 8 * gate * gate ? 1 : 0;
    }
  }
  EXPECT_GT(agreeing, 300);  // poses where some readings agree were tested
}

TEST(RegionStarts, OneResidualRuleForEveryCountOfAgreeingReadings)
{
  // The square room's east wall is x = 1: a ray east from (0.3, 0.2) meets it at 0.7 m.
  const auto map = test::loadMap("maps/square_room.poly");
  const Pose2 pose(0.3, 0.2, 0.0);
  Reading finite;
  finite.range = 0.6;
  EXPECT_NEAR(readingResidual(*map, pose, finite), 0.1, 1e-12);
  EXPECT_EQ(readingResidual(*map, pose, finite, 0.05), kInf);  // the cast cut at d + reach
  Reading no_return;
  no_return.range = kInf;
  no_return.max_range = 0.5;  // nothing within 0.5 m, as measured
  EXPECT_EQ(readingResidual(*map, pose, no_return), 0.0);
  no_return.max_range = 0.9;  // the wall at 0.7 m should have returned
  EXPECT_NEAR(readingResidual(*map, pose, no_return), -0.2, 1e-12);
  EXPECT_TRUE(std::isnan(readingResidual(*map, Pose2(1.5, 0.0, 0.0), finite)));  // outside
  // Its consumers: agreeing within eps when |r| < eps, contradicted when r <= -eps; the
  // certificate's count includes |r| = tolerance.
  const std::vector<Reading> readings{ finite, no_return };
  const PoseEvaluation e = evaluatePose(*map, pose, readings, 0.15);
  EXPECT_EQ(e.inliers, 1);
  EXPECT_EQ(e.contradicted, 1);
  EXPECT_EQ(consensusWithin(*map, pose, readings, 0.2 + 1e-9), 2);
  EXPECT_NEAR(agreementScore(*map, pose, readings, 0.15), 0.1 * 0.1 + 0.15 * 0.15, 1e-12);
}

TEST(RegionStarts, FreeStartMovesAStartInAWallIntoFreeSpace)
{
  const auto map = test::loadMap("maps/square_room.poly");
  const Pose2 in_wall(1.0 + 0.01, 0.2, 0.5);  // the square room's east wall is x = 1
  ASSERT_FALSE(map->isFree(in_wall.position()));
  const Pose2 moved = freeStart(*map, in_wall, 0.05);
  EXPECT_TRUE(map->isFree(moved.position()));
  EXPECT_LT((moved.position() - in_wall.position()).norm(), 0.05);
  EXPECT_EQ(moved.theta, in_wall.theta);
  const Pose2 free(0.3, 0.2, 0.5);
  EXPECT_EQ(freeStart(*map, free, 0.05).position(), free.position());
}

}  // namespace core
}  // namespace fdml_localization
