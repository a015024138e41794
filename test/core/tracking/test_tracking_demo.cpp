// The demo's relocalizations (make demo: config/scenarios/demo.yaml, launch/simulation.launch
// with config/localizer.yaml), ROS-free and without their timing: the robot kidnapped at random,
// the tracker cleared, global searches where the node runs them while relocalizing
// (SolverWorker::needsGlobalSearch), until one hypothesis is clearly supported: what ~relocalize
// answers.
#include "fdml_localization/core/tracking/hypothesis_tracker.h"
#include "localizer_test_utils.h"
#include "tracking_drive.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <string>

namespace core = fdml_localization::core;
using fdml_test::Drive;
using fdml_test::DriveBatch;

namespace
{
/// config/scenarios/demo.yaml with scenario seed @p seed: the robot turning in place at
/// 0.8 rad/s, four narrow cones (front, left, back, right) at 1.6 Hz with 1 cm noise, three
/// people walking at random and two chairs that are not in the map.
core::ScenarioConfig demoScenario(std::uint64_t seed)
{
  core::ScenarioConfig c;
  c.seed = seed;
  c.step_rate = 50;
  c.robot.radius = 0.18;
  c.robot.motion = core::RobotMotion::Rotate;
  c.robot.angular_speed = 0.8;
  c.sensors = fdml_test::fourSensors(1.6, 8.0, 0.01);
  for (core::SensorConfig& s : c.sensors)
  {
    s.fov = 0.04;
  }
  c.odometry.rate = 50;
  c.odometry.translation_noise = 0.005;
  c.odometry.rotation_noise = 0.005;
  c.obstacles.push_back(fdml_test::walkers(3, 0.2, 0.5));
  core::ObstacleGroupConfig chairs;
  chairs.count = 2;
  chairs.polygon = true;
  chairs.vertices = { { -0.22, -0.22 }, { 0.22, -0.22 }, { 0.22, 0.22 }, { -0.22, 0.22 } };
  c.obstacles.push_back(chairs);
  return c;
}

struct Answers
{
  int right = 0, wrong = 0, unanswered = 0;
  double seconds = 0.0;  ///< summed time from the kidnap to the answer [s]
  std::string first_wrong;
};

/// One relocalization after a kidnap to @p where: searches and updates on the batches of readings
/// taken there (k = 10, stride 1) for at most @p timeout [s] (the demo's ~relocalize_timeout).
void relocalize(Drive& drive, const core::Pose2& where, double timeout, core::HypothesisTracker& tracker,
                core::Localizer& global, Answers* answers)
{
  tracker.clear();
  const double start = drive.sim().time();
  core::Result found;
  core::Pose2 searched;
  bool pending = false;
  int since_global = 0;
  DriveBatch batch;
  while (drive.next(&batch, start + timeout))
  {
    if ((batch.truth.position() - where.position()).norm() > 1e-9)
    {
      continue;  // a reading from before the kidnap: ~relocalize waits for k fresh ones
    }
    if (pending)
    {
      tracker.seed(found.candidates, searched, 0.0);
      pending = false;
    }
    const core::TrackState state = tracker.state();
    const bool stuck = tracker.failedUpdates() >= 40 && since_global >= 40;
    if (state == core::TrackState::Empty || state == core::TrackState::Lost || stuck || tracker.awaitingConfirmation())
    {
      found = global.localize(batch.readings);
      searched = batch.reference;
      pending = !found.truncated;
      since_global = 0;
    }
    since_global += tracker.hypotheses().empty() ? 0 : 1;
    tracker.update(batch.readings, batch.reference);
    int published = 0;
    const std::string error = fdml_test::scorePublished(tracker, batch, &published, &answers->wrong);
    answers->first_wrong = answers->first_wrong.empty() ? error : answers->first_wrong;
    if (published > 0)
    {
      answers->right += error.empty() ? 1 : 0;
      answers->seconds += batch.time - start;
      return;
    }
  }
  ++answers->unanswered;
}

/// @p kidnaps relocalizations in the demo with scenario seed @p seed and the node's defaults
/// (config/localizer.yaml, simulation.launch's range_tolerance 0.03 m and resolution 120).
Answers demoKidnaps(std::uint64_t seed, int kidnaps)
{
  const auto map = core::test::loadMap("maps/apartment.poly");
  Drive drive(fdml_test::simulate(demoScenario(seed), map), 10, 1, true);
  const core::LocalizerOptions search = fdml_test::globalSearchOptions(120, 0.03);
  core::TrackerOptions o;
  o.range_tolerance = search.range_tolerance;
  o.agreement_tolerance = search.agreement_tolerance;
  o.fix_covariance_scale = 10.0;  // k / stride, as the node sets it
  core::HypothesisTracker tracker(map, o);
  core::Localizer global(map, search);
  Answers answers;
  for (int n = 0; n < kidnaps; ++n)
  {
    core::Pose2 where;
    std::string message;
    EXPECT_TRUE(drive.sim().kidnapRandom(&where, &message)) << message;
    relocalize(drive, where, 30.0, tracker, global, &answers);
  }
  return answers;
}
}  // namespace

TEST(HypothesisTrackerDemo, KidnapsAmongPeopleAndChairsAreNeverAnsweredWrong)
{
  // Without a confirming search (~confirm_searches 0) each of these runs answered one kidnap
  // wrong, one search having returned a single place alike: at seed 22 the 48th kidnap, to
  // (11.15, 2.51), was answered 5.6 m away at the map's mirrored place, which explained 8 of
  // the 10 readings (three on people and chairs) while the truth explained 7. The later search
  // brings the true place to compete.
  const std::pair<std::uint64_t, int> runs[] = { { 18, 53 }, { 22, 49 }, { 25, 51 }, { 39, 59 } };
  int answered = 0, kidnaps = 0;
  for (const auto& run : runs)
  {
    const Answers answers = demoKidnaps(run.first, run.second);
    EXPECT_EQ(answers.wrong, 0) << "seed " << run.first << ": " << answers.first_wrong;
    answered += answers.right + answers.wrong;
    kidnaps += run.second;
    std::printf("seed %llu: %d kidnaps, %d right, %d wrong, %d unanswered, %.2f s to the answer on average\n",
                static_cast<unsigned long long>(run.first), run.second, answers.right, answers.wrong,
                answers.unanswered, answers.seconds / std::max(1, answers.right + answers.wrong));
  }
  EXPECT_GE(answered, kidnaps - 2);
}
