// The hypothesis tracker over the office drive as test/rostest/tracking_office.test runs it
// (config/scenarios/office_moving.yaml, the launch's tracker settings, global searches as the node
// starts them), ROS-free and without its timing: the drive that published a pose 6 degrees off.
#include "fdml_localization/core/tracking/hypothesis_tracker.h"
#include "localizer_test_utils.h"
#include "tracking_drive.h"

#include <gtest/gtest.h>

#include <string>

namespace core = fdml_localization::core;
using fdml_test::Drive;
using fdml_test::DriveBatch;

namespace
{
/// config/scenarios/office_moving.yaml with scenario seed @p seed: the robot up and down the 16 m
/// corridor, three narrow cones (front, left, right) at 10 Hz with 2 cm noise and 5 % dropout,
/// four people walking the corridor and six wandering.
core::ScenarioConfig officeMoving(std::uint64_t seed)
{
  core::ScenarioConfig c = fdml_test::waypointScenario({ { 1.5, 5.7 }, { 16.5, 5.7 } }, 10.0, 0.03, seed);
  c.robot.radius = 0.2;
  c.robot.linear_speed = 0.5;
  c.robot.angular_speed = 1.0;
  c.sensors.erase(c.sensors.begin() + 2);  // front, left, right (mounts as in the YAML): no back sensor
  c.sensors[0].mount = core::Pose2(0.2, 0.0, 0.0);
  c.sensors[1].mount = core::Pose2(0.0, 0.2, 1.5708);
  c.sensors[2].mount = core::Pose2(0.0, -0.2, -1.5708);
  for (core::SensorConfig& s : c.sensors)
  {
    s.fov = 0.04;
    s.noise_sigma = 0.02;
    s.dropout = 0.05;
  }
  c.obstacles.push_back(fdml_test::pacers(2, 0.25, 0.9, { { 1.0, 5.15 }, { 17.0, 5.15 } }));
  c.obstacles.push_back(fdml_test::pacers(2, 0.25, 0.7, { { 16.5, 6.25 }, { 1.0, 6.25 } }));
  c.obstacles.push_back(fdml_test::walkers(6, 0.25, 0.6));
  return c;
}

struct OfficeRun
{
  int updates = 0, published = 0, wrong = 0;
  std::string first_wrong;
};

/// Drives officeMoving(@p seed) for @p duration [s] with k = 10, stride 2, kidnapped at 60 s to
/// (10, 5.7, 3.0) as the launch does, running a global search
/// (adaptive, 120 cells) whenever the node would (HypothesisTracker::wantsGlobalSearch), its
/// candidates seeded 1 s of batches later as from the node's worker.
OfficeRun driveOffice(std::uint64_t seed, double duration)
{
  const auto map = core::test::loadMap("maps/office.poly");
  Drive drive(fdml_test::simulate(officeMoving(seed), map), 10, 2);
  const core::LocalizerOptions search = fdml_test::globalSearchOptions(120, 0.03);
  // The launch's tracker: the simulated odometry's noise, range_tolerance 0.03 m, k / stride = 5.
  core::HypothesisTracker tracker(map, fdml_test::launchTrackerOptions(core::TrackerOptions(), search, true));
  core::Localizer global(map, search);
  OfficeRun run;
  DriveBatch batch;
  core::Result pending;
  core::Pose2 searched;
  double due = -1.0;
  std::size_t since = 0;
  int since_global = 40;
  bool kidnapped = false;
  while (drive.next(&batch, duration))
  {
    if (!kidnapped && batch.time >= 60.0)
    {
      std::string message;
      kidnapped = drive.sim().kidnap(core::Pose2(10.0, 5.7, 3.0), &message);
      EXPECT_TRUE(kidnapped) << message;
      kidnapped = true;
      continue;
    }
    tracker.update(batch.readings, batch.reference);
    ++since_global;
    if (due >= 0.0 && (++since, batch.time >= due))
    {
      tracker.seed(pending.candidates, searched, 0.0, since);
      due = -1.0;
    }
    else if (due < 0.0)
    {
      if (tracker.wantsGlobalSearch(true, since_global, 40))  // continuous mode, ~global_interval 40
      {
        pending = global.localize(batch.readings);
        searched = batch.reference;
        due = batch.time + 1.0;
        since = 0;
        since_global = 0;
      }
    }
    ++run.updates;
    const std::string error = fdml_test::scorePublished(tracker, batch, &run.published, &run.wrong);
    run.first_wrong = run.first_wrong.empty() ? error : run.first_wrong;
  }
  return run;
}
}  // namespace

TEST(HypothesisTrackerOffice, APersonReadAsAWallAtASlantMovesNoPublishedPose)
{
  // At 113.8 s, turning at the corridor's east end, the front cone's readings hit a person 6.7 m
  // away; a heading 3.6 then 6.3 degrees off explains them as the side wall at a slant, one
  // reading more than the truth. That fix disagreed with the precise prediction (squared
  // Mahalanobis 32), and the one-direction loss of its covariance covered the position along
  // the corridor, not the heading: the tracker followed it and published it 6.3 degrees off,
  // claiming 0.3 degrees (3 sigma), for 0.8 s. A disagreeing fix now counts only up to its
  // disagreement.
  const OfficeRun run = driveOffice(3, 116.0);
  EXPECT_GT(run.updates, 1100);
  EXPECT_GT(run.published, 250);
  EXPECT_EQ(run.wrong, 0) << run.first_wrong;
}
