// Relocalizations replayed ROS-free, as the node runs them (used by HypothesisTrackerDemo and the
// replay_relocalizations tool): the robot kidnapped at random, the tracker cleared, global
// searches where the node runs them while relocalizing (HypothesisTracker::wantsGlobalSearch) (seeded at the next
// batch), until one hypothesis is clearly supported: what ~relocalize answers.
#pragma once

#include "fdml_localization/core/tracking/hypothesis_tracker.h"
#include "tracking_drive.h"

#include <memory>
#include <stdexcept>
#include <string>

namespace fdml_test
{
/// config/scenarios/demo.yaml with scenario seed @p seed: the robot turning in place at
/// 0.8 rad/s, four narrow cones (front, left, back, right) at 1.6 Hz with 1 cm noise, three
/// people walking at random and two chairs that are not in the map.
inline core::ScenarioConfig demoScenario(std::uint64_t seed)
{
  core::ScenarioConfig c;
  c.seed = seed;
  c.step_rate = 50;
  c.robot.radius = 0.18;
  c.robot.motion = core::RobotMotion::Rotate;
  c.robot.angular_speed = 0.8;
  c.sensors = fourSensors(1.6, 8.0, 0.01);
  for (core::SensorConfig& s : c.sensors)
  {
    s.fov = 0.04;
  }
  c.odometry.rate = 50;
  c.odometry.translation_noise = 0.005;
  c.odometry.rotation_noise = 0.005;
  c.obstacles.push_back(walkers(3, 0.2, 0.5));
  core::ObstacleGroupConfig chairs;
  chairs.count = 2;
  chairs.polygon = true;
  chairs.vertices = { { -0.22, -0.22 }, { 0.22, -0.22 }, { 0.22, 0.22 }, { -0.22, 0.22 } };
  c.obstacles.push_back(chairs);
  return c;
}

/// What the relocalizations answered.
struct ReplayAnswers
{
  int right = 0, wrong = 0, unanswered = 0;
  double seconds = 0.0;  ///< summed time from the kidnap to the answer [s]
  std::string first_wrong;
  /// With a follow time: the updates after the answers that published a pose, and the wrong ones.
  int followed_published = 0, followed_wrong = 0;
};

/// How long a replayed relocalization runs [s of simulated time].
struct ReplayTiming
{
  double timeout = 30.0;  ///< at most this long from the kidnap to an answer
  double follow = 0.0;    ///< tracking goes on this long after the answer, scored
  /// > 0: every kidnap runs exactly this long (the answer within it, followed to its end), so the
  /// kidnaps and the people do not depend on when the answers came: builds compare kidnap by
  /// kidnap. Replaces timeout and follow.
  double window = 0.0;

  /// The simulated time to drive to after a kidnap at @p kidnapped, answered at @p answered (< 0:
  /// not yet).
  double end(double kidnapped, double answered) const
  {
    return window > 0.0 ? kidnapped + window : answered < 0.0 ? kidnapped + timeout : answered + follow;
  }
  bool following() const
  {
    return follow > 0.0 || window > 0.0;
  }
};

/// One relocalization after a kidnap at simulated time @p kidnapped [s]: searches and updates on
/// the batches of readings all taken after it until an answer (ReplayTiming); then, while
/// @p timing follows, the same updates go on (tracking, as the node does) and what they publish
/// is scored.
inline void relocalize(Drive& drive, double kidnapped, const ReplayTiming& timing, core::HypothesisTracker& tracker,
                       core::Localizer& global, ReplayAnswers* answers)
{
  tracker.clear();
  core::Result found;
  core::Pose2 searched;
  bool pending = false;
  int since_global = 0;
  DriveBatch batch;
  double answered = -1.0;  // simulated time of the answer [s]
  while (drive.next(&batch, timing.end(kidnapped, answered)))
  {
    if (batch.start_time <= kidnapped)
    {
      continue;  // ~relocalize waits for k readings taken after the request
    }
    if (pending)
    {
      tracker.seed(found.candidates, searched, 0.0);
      pending = false;
    }
    if (tracker.wantsGlobalSearch(true, since_global, 40))  // ~global_interval 40
    {
      found = global.localize(batch.readings);
      searched = batch.reference;
      pending = !found.truncated;
      since_global = 0;
    }
    since_global += tracker.hypotheses().empty() ? 0 : 1;
    tracker.update(batch.readings, batch.reference);
    if (answered >= 0.0)
    {
      scorePublished(tracker, batch, &answers->followed_published, &answers->followed_wrong);
      continue;
    }
    int published = 0;
    const std::string error = scorePublished(tracker, batch, &published, &answers->wrong);
    answers->first_wrong = answers->first_wrong.empty() ? error : answers->first_wrong;
    if (published > 0)
    {
      answers->right += error.empty() ? 1 : 0;
      answers->seconds += batch.time - kidnapped;
      answered = batch.time;
      if (!timing.following())
      {
        return;
      }
    }
  }
  answers->unanswered += answered < 0.0 ? 1 : 0;
}

/// @p kidnaps relocalizations (each as long as @p timing) in @p scenario on @p map, batches of
/// @p k readings sliding by @p stride (formed per reading, as the node forms them), @p tracker
/// and @p search the node's tracker and tracking global search.
inline ReplayAnswers replayKidnaps(const core::ScenarioConfig& scenario, std::shared_ptr<const core::MapRayCaster> map,
                                   int k, int stride, const core::TrackerOptions& tracker_options,
                                   const core::LocalizerOptions& search, int kidnaps, const ReplayTiming& timing)
{
  Drive drive(simulate(scenario, map), k, stride, true);
  core::HypothesisTracker tracker(map, tracker_options);
  core::Localizer global(map, search);
  ReplayAnswers answers;
  for (int n = 0; n < kidnaps; ++n)
  {
    core::Pose2 where;
    std::string message;
    if (!drive.sim().kidnapRandom(&where, &message))
    {
      throw std::runtime_error("kidnap: " + message);
    }
    relocalize(drive, drive.sim().time(), timing, tracker, global, &answers);
  }
  return answers;
}

}  // namespace fdml_test
