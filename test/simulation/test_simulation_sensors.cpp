// Tests of the simulator core's sensors, odometry, robot motion, kidnapping and reset, each
// against an independent computation (the map's own ray cast, pose algebra, statistics).
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/simulation/simulation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace core = fdml_localization::core;
using core::Pose2;
using core::Vec2;

namespace
{
/// A 4 x 3 m room with a 1 x 0.6 m pillar in the middle.
std::shared_ptr<const core::MapRayCaster> roomWithPillar()
{
  std::vector<core::Ring> rings = { { Vec2(0, 0), Vec2(4, 0), Vec2(4, 3), Vec2(0, 3) },
                                    { Vec2(1.5, 1.2), Vec2(2.5, 1.2), Vec2(2.5, 1.8), Vec2(1.5, 1.8) } };
  return std::make_shared<core::MapRayCaster>(core::PolygonMap::fromRings(rings, "pillar_room"));
}

core::SensorConfig sensor(const std::string& frame, const Pose2& mount, double rate, double max_range)
{
  core::SensorConfig s;
  s.frame = frame;
  s.mount = mount;
  s.rate = rate;
  s.max_range = max_range;
  return s;
}

/// A scenario of a robot driving around the pillar with three noise-free sensors.
core::ScenarioConfig loopScenario()
{
  core::ScenarioConfig c;
  c.map_file = "pillar_room";
  c.step_rate = 50.0;
  c.robot.radius = 0.2;
  c.robot.motion = core::RobotMotion::Waypoints;
  c.robot.linear_speed = 0.6;
  c.robot.angular_speed = 1.5;
  c.robot.waypoints = { Vec2(0.5, 0.5), Vec2(3.5, 0.5), Vec2(3.5, 2.5), Vec2(0.5, 2.5) };
  c.sensors = { sensor("front", Pose2(0.1, 0.0, 0.0), 10.0, 5.0), sensor("left", Pose2(0.0, 0.1, 1.5708), 25.0, 1.0),
                sensor("back", Pose2(-0.1, 0.05, 3.0), 50.0, 8.0) };
  // A ray, the default narrow cone (0.05 rad) and a 27 deg cone.
  c.sensors[0].fov = 0.0;
  c.sensors[2].fov = 27.0 * core::kPi / 180.0;
  return c;
}

std::unique_ptr<core::Simulation> make(const core::ScenarioConfig& c)
{
  std::vector<std::string> errors;
  auto sim = core::Simulation::create(c, roomWithPillar(), &errors);
  EXPECT_TRUE(errors.empty()) << (errors.empty() ? "" : errors.front());
  return sim;
}
}  // namespace

TEST(SimulationSensors, NoiseFreeReadingsEqualTheMapConeCastAtTheTrueSensorPose)
{
  const core::ScenarioConfig c = loopScenario();
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  core::StepOutput out;
  int count[3] = { 0, 0, 0 };
  int misses = 0;
  for (int step = 0; step < 1000; ++step)
  {
    sim->step(&out);
    for (const core::SimReading& r : out.readings)
    {
      const Pose2 pose = core::compose(sim->truePose(), c.sensors[static_cast<std::size_t>(r.sensor)].mount);
      EXPECT_NEAR(r.sensor_pose.x, pose.x, 1e-12);
      EXPECT_NEAR(r.sensor_pose.y, pose.y, 1e-12);
      const core::SensorConfig& s = c.sensors[static_cast<std::size_t>(r.sensor)];
      const double expected = core::coneRange(sim->scene().map(), pose, 0.5 * s.fov, s.max_range);
      EXPECT_EQ(r.range, expected);
      EXPECT_EQ(r.map_range, expected);
      EXPECT_EQ(r.kind, std::isinf(expected) ? core::SceneHit::Kind::None : core::SceneHit::Kind::Map);
      EXPECT_FALSE(r.dropped);
      EXPECT_NEAR(r.time, sim->time(), 1e-12);
      count[r.sensor]++;
      misses += std::isinf(expected) ? 1 : 0;
    }
  }
  // 20 s at 10, 25 and 50 Hz.
  EXPECT_EQ(count[0], 200);
  EXPECT_EQ(count[1], 500);
  EXPECT_EQ(count[2], 1000);
  EXPECT_GT(misses, 0);
}

TEST(SimulationSensors, NoiseAndDropoutHaveTheConfiguredStatistics)
{
  core::ScenarioConfig c;
  c.map_file = "pillar_room";
  c.step_rate = 50.0;
  c.robot.random_start = false;
  c.robot.start = Pose2(0.8, 0.8, 0.0);
  c.robot.angular_speed = 0.7;
  core::SensorConfig s = sensor("s", Pose2(), 50.0, 10.0);
  s.noise_sigma = 0.05;
  s.dropout = 0.3;
  c.sensors = { s };
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  core::StepOutput out;
  double sum = 0.0;
  double sum2 = 0.0;
  int n = 0;
  int dropped = 0;
  int total = 0;
  for (int step = 0; step < 5000; ++step)
  {
    sim->step(&out);
    for (const core::SimReading& r : out.readings)
    {
      ++total;
      dropped += r.dropped ? 1 : 0;
      ASSERT_EQ(r.kind, core::SceneHit::Kind::Map);
      const double e = r.range - r.true_range;
      sum += e;
      sum2 += e * e;
      ++n;
    }
  }
  ASSERT_EQ(total, 5000);
  const double mean = sum / n;
  const double sigma = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 4.0 * 0.05 / std::sqrt(n));
  EXPECT_NEAR(sigma, 0.05, 0.005);
  const double p = static_cast<double>(dropped) / total;
  EXPECT_NEAR(p, 0.3, 4.0 * std::sqrt(0.3 * 0.7 / total));
}

TEST(SimulationSensors, RangeLimitsFollowRep117)
{
  core::ScenarioConfig c;
  c.map_file = "pillar_room";
  c.robot.random_start = false;
  c.robot.start = Pose2(0.3, 1.0, core::kPi);  // facing the wall at x = 0, 0.3 m away
  c.robot.radius = 0.1;
  c.robot.angular_speed = 0.0;
  core::SensorConfig near_sensor = sensor("near", Pose2(), 10.0, 5.0);
  near_sensor.min_range = 0.5;
  core::SensorConfig short_sensor = sensor("short", Pose2(0.0, 0.0, core::kPi), 10.0, 0.5);  // faces +x
  c.sensors = { near_sensor, short_sensor };
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  core::StepOutput out;
  sim->step(&out);
  ASSERT_EQ(out.readings.size(), 2u);
  EXPECT_TRUE(std::isinf(out.readings[0].range) && out.readings[0].range < 0.0);  // too close: -inf
  EXPECT_NEAR(out.readings[0].true_range, 0.3, 1e-12);
  EXPECT_TRUE(std::isinf(out.readings[1].range) && out.readings[1].range > 0.0);  // nothing in range: +inf
  EXPECT_EQ(out.readings[1].kind, core::SceneHit::Kind::None);
}

TEST(SimulationSensors, ScanBeamsEqualMapCasts)
{
  core::ScenarioConfig c = loopScenario();
  c.scan.enabled = true;
  c.scan.beams = 12;
  c.scan.rate = 5.0;
  c.scan.mount = Pose2(0.05, 0.0, 0.3);
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  core::StepOutput out;
  int scans = 0;
  for (int step = 0; step < 500; ++step)
  {
    sim->step(&out);
    if (!out.has_scan)
    {
      continue;
    }
    ++scans;
    ASSERT_EQ(out.scan.ranges.size(), 12u);
    const Pose2 base = core::compose(sim->truePose(), c.scan.mount);
    for (int b = 0; b < 12; ++b)
    {
      const Pose2 beam = core::compose(base, Pose2(0.0, 0.0, -core::kPi + b * core::kTwoPi / 12));
      EXPECT_NEAR(out.scan.ranges[static_cast<std::size_t>(b)], sim->scene().map().range(beam, c.scan.max_range), 1e-9);
    }
  }
  EXPECT_EQ(scans, 50);
}

TEST(SimulationOdometry, DriftFreeOdometryComposesToTheTruePose)
{
  auto sim = make(loopScenario());
  ASSERT_NE(sim, nullptr);
  const Pose2 start = sim->truePose();
  core::StepOutput out;
  for (int step = 0; step < 3000; ++step)
  {
    sim->step(&out);
    const Pose2 predicted = core::compose(start, sim->odomPose());
    ASSERT_NEAR(predicted.x, sim->truePose().x, 1e-9);
    ASSERT_NEAR(predicted.y, sim->truePose().y, 1e-9);
    ASSERT_NEAR(core::angleDiff(predicted.theta, sim->truePose().theta), 0.0, 1e-9);
  }
  EXPECT_GT((sim->truePose().position() - start.position()).norm() + std::abs(sim->truePose().theta), 0.1);
}

TEST(SimulationOdometry, DriftGrowsAndIsReproducibleFromTheSeed)
{
  core::ScenarioConfig c = loopScenario();
  c.odometry.translation_noise = 0.05;
  c.odometry.rotation_noise = 0.05;
  auto a = make(c);
  auto b = make(c);
  c.seed = 99;
  auto other = make(c);
  ASSERT_TRUE(a && b && other);
  const Pose2 start = a->truePose();
  core::StepOutput out;
  for (int step = 0; step < 3000; ++step)
  {
    a->step(&out);
    b->step(&out);
    other->step(&out);
  }
  EXPECT_EQ(a->odomPose().x, b->odomPose().x);
  EXPECT_EQ(a->odomPose().theta, b->odomPose().theta);
  EXPECT_NE(a->odomPose().x, other->odomPose().x);
  const Pose2 predicted = core::compose(start, a->odomPose());
  EXPECT_GT((predicted.position() - a->truePose().position()).norm(), 1e-3);
}

TEST(SimulationRobot, WaypointLoopVisitsEveryWaypoint)
{
  const core::ScenarioConfig c = loopScenario();
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  std::vector<bool> visited(c.robot.waypoints.size(), false);
  core::StepOutput out;
  for (int step = 0; step < 2500; ++step)
  {
    sim->step(&out);
    for (std::size_t i = 0; i < visited.size(); ++i)
    {
      visited[i] = visited[i] || (sim->truePose().position() - c.robot.waypoints[i]).norm() < 1e-9;
    }
  }
  for (std::size_t i = 0; i < visited.size(); ++i)
  {
    EXPECT_TRUE(visited[i]) << "waypoint " << i;
  }
}

TEST(SimulationRobot, CmdVelStopsAtWallsAndExpires)
{
  core::ScenarioConfig c;
  c.map_file = "pillar_room";
  c.step_rate = 50.0;
  c.robot.random_start = false;
  c.robot.start = Pose2(1.0, 0.5, 0.0);
  c.robot.motion = core::RobotMotion::CmdVel;
  c.robot.cmd_vel_timeout = 0.5;
  c.sensors = { sensor("s", Pose2(), 10.0, 5.0) };
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  core::StepOutput out;
  for (int step = 0; step < 500; ++step)  // 10 s at 1 m/s towards the wall at x = 4
  {
    if (step % 10 == 0)
    {
      sim->setVelocityCommand(5.0, 0.0);  // clamped to max_linear_speed
    }
    sim->step(&out);
    ASSERT_LE(sim->linearVelocity(), c.robot.max_linear_speed + 1e-12);
    ASSERT_LE(sim->truePose().x, 4.0 - c.robot.radius);
  }
  EXPECT_GT(sim->truePose().x, 4.0 - c.robot.radius - 2.0 * c.robot.max_linear_speed / c.step_rate - c.clearance);
  sim->setVelocityCommand(-0.5, 1.0);
  for (int step = 0; step < 100; ++step)
  {
    sim->step(&out);
  }
  const Pose2 stopped = sim->truePose();
  for (int step = 0; step < 50; ++step)
  {
    sim->step(&out);
  }
  EXPECT_EQ(sim->truePose().x, stopped.x) << "the command should have expired after 0.5 s";
  EXPECT_EQ(sim->truePose().theta, stopped.theta);
}

TEST(SimulationRobot, KidnapMovesTheTruthNotOdometryAndResetRestores)
{
  core::ScenarioConfig c = loopScenario();
  c.obstacles.resize(1);
  c.obstacles[0].count = 4;
  c.obstacles[0].motion = core::ObstacleMotion::Bounce;
  auto sim = make(c);
  ASSERT_NE(sim, nullptr);
  const Pose2 initial = sim->truePose();
  const Vec2 initial_obstacle = sim->obstacleStates()[0].position;
  core::StepOutput out;
  for (int step = 0; step < 100; ++step)
  {
    sim->step(&out);
  }
  const Pose2 odom = sim->odomPose();
  std::string message;
  EXPECT_FALSE(sim->kidnap(Pose2(2.0, 1.5, 0.0), &message));  // inside the pillar
  EXPECT_FALSE(message.empty());
  // A target well away from every (moving) obstacle.
  Pose2 target;
  bool found = false;
  for (const Vec2& p : { Vec2(3.0, 2.2), Vec2(0.6, 2.4), Vec2(3.4, 0.6), Vec2(0.6, 0.6), Vec2(3.0, 1.5) })
  {
    bool clear = true;
    for (const auto& o : sim->obstacleStates())
    {
      clear = clear && (o.position - p).norm() > 0.6;
    }
    if (clear && !found)
    {
      target = Pose2(p.x(), p.y(), 2.0);
      found = true;
    }
  }
  ASSERT_TRUE(found);
  ASSERT_TRUE(sim->kidnap(target, &message)) << message;
  EXPECT_EQ(sim->truePose().x, target.x);
  EXPECT_EQ(sim->truePose().theta, target.theta);
  EXPECT_EQ(sim->odomPose().x, odom.x);
  EXPECT_EQ(sim->odomPose().y, odom.y);
  Pose2 random;
  ASSERT_TRUE(sim->kidnapRandom(&random, &message)) << message;
  EXPECT_TRUE(sim->robotFits(random.position()));
  EXPECT_EQ(sim->truePose().x, random.x);
  sim->reset();
  EXPECT_EQ(sim->truePose().x, initial.x);
  EXPECT_EQ(sim->truePose().y, initial.y);
  EXPECT_EQ(sim->odomPose().x, 0.0);
  EXPECT_EQ(sim->obstacleStates()[0].position, initial_obstacle);
}
