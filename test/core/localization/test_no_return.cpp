// LocalizerOptions::no_return: constraint (the default), weak (tie-break only) and drop, on a
// room with a corridor off one end: the readings with a return cannot tell the robot at
// (8, 2) facing +x from its 180-degree twin at (2, 2) facing -x; a no-return along the
// corridor can.
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/no_return.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

namespace core = fdml_localization::core;

namespace
{
std::shared_ptr<const core::MapRayCaster> roomWithCorridor()
{
  const core::Ring outer = { { 0, 0 },    { 10, 0 },   { 10, 1.5 }, { 30, 1.5 },
                             { 30, 2.5 }, { 10, 2.5 }, { 10, 4 },   { 0, 4 } };
  return std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings({ outer }));
}

const core::Pose2 kTruth(8.0, 2.0, 0.0);
const core::Pose2 kTwin(2.0, 2.0, core::kPi);
constexpr double kMaxRange = 10.0;

core::Reading reading(const core::MapRayCaster& map, double angle, bool no_return)
{
  core::Reading r;
  r.offset = core::Pose2(0.0, 0.0, angle);
  r.max_range = kMaxRange;
  const double h = map.range(core::compose(kTruth, r.offset), kMaxRange + 1.0);
  r.range = no_return || h > kMaxRange ? core::kInf : h;
  return r;
}

/// Six returns symmetric under the twin, plus no-returns at @p no_return_angles.
std::vector<core::Reading> readings(const core::MapRayCaster& map, const std::vector<double>& no_return_angles)
{
  std::vector<core::Reading> out;
  for (double deg : { 20.0, -20.0, 90.0, -90.0, 160.0, -160.0 })
  {
    out.push_back(reading(map, deg * core::kPi / 180.0, false));
  }
  for (double angle : no_return_angles)
  {
    out.push_back(reading(map, angle, true));
  }
  return out;
}

bool near(const core::Pose2& a, const core::Pose2& b)
{
  return (a.position() - b.position()).norm() < 0.05 && std::abs(core::angleDiff(a.theta, b.theta)) < 0.035;
}

core::Result run(core::NoReturnPolicy policy, const std::vector<core::Reading>& batch)
{
  core::LocalizerOptions options;
  options.no_return = policy;
  core::Localizer localizer(roomWithCorridor(), options);
  return localizer.localize(batch);
}
}  // namespace

TEST(NoReturn, NamesParseAndValidate)
{
  for (core::NoReturnPolicy p :
       { core::NoReturnPolicy::Constraint, core::NoReturnPolicy::Weak, core::NoReturnPolicy::Drop })
  {
    EXPECT_EQ(core::parseNoReturn(core::toString(p)), p);
  }
  EXPECT_THROW(core::parseNoReturn("ignore"), std::invalid_argument);
  core::LocalizerOptions options;
  EXPECT_TRUE(core::validate(options).empty());
  options.no_return = static_cast<core::NoReturnPolicy>(7);
  const std::vector<std::string> errors = core::validate(options);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("no_return"), std::string::npos) << errors[0];
}

TEST(NoReturn, WeakBreaksTheTieAConstraintDecides)
{
  const auto map = roomWithCorridor();
  const std::vector<core::Reading> batch = readings(*map, { 0.0 });  // down the corridor: agrees at the truth only
  const core::Result constraint = run(core::NoReturnPolicy::Constraint, batch);
  ASSERT_FALSE(constraint.candidates.empty());
  EXPECT_TRUE(near(constraint.candidates[0].pose, kTruth));
  EXPECT_EQ(constraint.candidates[0].inliers, 7);

  const core::Result weak = run(core::NoReturnPolicy::Weak, batch);
  ASSERT_GE(weak.candidates.size(), 2u);
  EXPECT_TRUE(near(weak.candidates[0].pose, kTruth));
  EXPECT_TRUE(near(weak.candidates[1].pose, kTwin));
  for (const core::Candidate& c : { weak.candidates[0], weak.candidates[1] })
  {
    EXPECT_EQ(c.inliers, 6);       // the no-return is neither an inlier ...
    EXPECT_EQ(c.contradicted, 0);  // ... nor contradicted, even at the twin
    ASSERT_EQ(c.inlier_mask.size(), batch.size());
    EXPECT_FALSE(c.inlier_mask[6]);
  }
  EXPECT_EQ(weak.readings_used, 6);
}

TEST(NoReturn, GlassNoReturnsAreDroppedOrWeakInsteadOfContradicting)
{
  const auto map = roomWithCorridor();
  // A lidar seeing no echo from the side walls (glass) 2 m away, and one down the corridor.
  const std::vector<core::Reading> batch = readings(*map, { 0.0, core::kPi / 2, -core::kPi / 2 });
  const core::Result constraint = run(core::NoReturnPolicy::Constraint, batch);
  for (const core::Candidate& c : constraint.candidates)
  {
    if (near(c.pose, kTruth))
    {
      EXPECT_EQ(c.contradicted, 2);  // the glass contradicts the truth
    }
  }
  for (core::NoReturnPolicy policy : { core::NoReturnPolicy::Weak, core::NoReturnPolicy::Drop })
  {
    const core::Result result = run(policy, batch);
    ASSERT_FALSE(result.candidates.empty()) << core::toString(policy);
    const core::Candidate& best = result.candidates[0];
    EXPECT_EQ(best.contradicted, 0) << core::toString(policy);
    EXPECT_EQ(best.inliers, 6) << core::toString(policy);
    EXPECT_EQ(best.inlier_mask.size(), batch.size()) << core::toString(policy);
    EXPECT_TRUE(near(best.pose, kTruth) || near(best.pose, kTwin)) << core::toString(policy);
  }
  EXPECT_TRUE(near(run(core::NoReturnPolicy::Weak, batch).candidates[0].pose, kTruth));
}

TEST(NoReturn, DropNeedsThreeReturns)
{
  const auto map = roomWithCorridor();
  std::vector<core::Reading> batch = readings(*map, { 0.0, 1.0, 2.0 });
  batch.erase(batch.begin(), batch.begin() + 4);  // 2 returns, 3 no-returns
  try
  {
    run(core::NoReturnPolicy::Drop, batch);
    ADD_FAILURE() << "expected InvalidInput";
  }
  catch (const core::InvalidInput& e)
  {
    EXPECT_NE(std::string(e.what()).find("no_return = drop: only 2 of 5 readings have a return"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(run(core::NoReturnPolicy::Constraint, batch));
}

TEST(NoReturn, OnlyNoReturnsGiveAnUndeterminedPoseNeverACertainOne)
{
  // Four no-returns 1 m long: every pose 1 m clear of the walls in the sensors' four directions
  // explains them; a candidate must say it is undetermined, not certain. The seeds' starts no
  // refinement beat (none has three finite readings to polish on) left with a zero covariance.
  const auto map = roomWithCorridor();
  std::vector<core::Reading> batch;
  for (int i = 0; i < 4; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.0, 0.0, i * core::kPi / 2);
    r.max_range = 1.0;
    r.range = core::kInf;
    batch.push_back(r);
  }
  for (core::Engine engine : { core::Engine::Voxel, core::Engine::Adaptive })
  {
    core::LocalizerOptions options;
    options.engine = engine;
    options.threads = 1;
    core::Localizer localizer(map, options);
    const core::Result result = localizer.localize(batch);
    ASSERT_FALSE(result.candidates.empty()) << core::toString(engine);
    EXPECT_EQ(result.candidates[0].inliers, 4) << core::toString(engine);
    for (const core::Candidate& c : result.candidates)
    {
      // At least the spread of a uniform pose over the 10 m by 4 m room and every heading
      // (2.9 m, 1.2 m, 1.8 rad), not a false certainty (a zero covariance widened only along the
      // directions probed: 1.2 m and 0.6 rad).
      const std::string at = " at (" + std::to_string(c.pose.x) + ", " + std::to_string(c.pose.y) + ")";
      EXPECT_GT(std::sqrt(c.covariance(0, 0)), 2.0) << core::toString(engine) << at;
      EXPECT_GT(std::sqrt(c.covariance(1, 1)), 1.0) << core::toString(engine) << at;
      EXPECT_GT(std::sqrt(c.covariance(2, 2)), 1.0) << core::toString(engine) << at;
    }
  }
}

TEST(NoReturnPolish, KeepsClearOfTheWallsANoReturnExcludes)
{
  // A 4 m square room; two returns, left and right (2 m each), fix y and the heading and leave
  // x free; a no-return ahead with a 1.5 m max range keeps x <= 2.5. From x = 3.5 (the wall
  // 0.5 m ahead) the polish moves x only through the no-return's one-sided bound.
  const core::MapRayCaster room(core::PolygonMap::fromRings({ { { 0, 0 }, { 4, 0 }, { 4, 4 }, { 0, 4 } } }));
  std::vector<core::Reading> readings(3);
  readings[0].offset = core::Pose2(0.0, 0.0, 0.5 * core::kPi);
  readings[1].offset = core::Pose2(0.0, 0.0, -0.5 * core::kPi);
  readings[0].range = readings[1].range = 2.0;
  readings[2].range = core::kInf;
  readings[2].max_range = 1.5;
  const core::Pose2 start(3.5, 1.8, 0.05);
  const core::PolishOutcome bounded = core::polishPose(room, start, readings, { true, true, true }, 0.0, 50, 0.01);
  EXPECT_NEAR(bounded.pose.x, 2.5, 1e-3);  // moved only as far as the bound needs
  EXPECT_NEAR(bounded.pose.y, 2.0, 1e-6);
  EXPECT_NEAR(bounded.pose.theta, 0.0, 1e-6);
  const core::PoseEvaluation eval = core::evaluatePose(room, bounded.pose, readings, 0.01);
  EXPECT_EQ(eval.inliers, 3);
  EXPECT_EQ(eval.contradicted, 0);
  EXPECT_GT(bounded.covariance(0, 0), 1.0);  // a bound adds nothing to the covariance: x stays free
  // Not selected, the no-return does not move the pose.
  const core::PolishOutcome free = core::polishPose(room, start, readings, { true, true, false }, 0.0, 50, 0.01);
  EXPECT_NEAR(free.pose.x, 3.5, 1e-6);
  EXPECT_EQ(core::evaluatePose(room, free.pose, readings, 0.01).contradicted, 1);
}
