// The simulator's cone sensors (fov > 0): every noise-free reading is the nearest point of the
// map or an obstacle within +-fov/2 of the sensor's axis, against brute force (the map's edges
// one by one; each disc by a dense fan of rays; each polygon by its edges), and its label (map or
// which obstacle) is right.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/simulation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

namespace core = fdml_localization::core;
using core::Pose2;
using core::Vec2;

namespace
{
constexpr double kFov = 27.0 * core::kPi / 180.0;

core::ScenarioConfig coneScenario()
{
  core::ScenarioConfig c;
  c.map_file = "apartment";
  c.seed = 5;
  c.step_rate = 50.0;
  c.robot.motion = core::RobotMotion::Rotate;
  c.robot.angular_speed = 0.7;
  for (int i = 0; i < 4; ++i)
  {
    core::SensorConfig s;
    s.frame = "tof" + std::to_string(i);
    s.mount = Pose2(0.15 * std::cos(i * core::kPi / 2), 0.15 * std::sin(i * core::kPi / 2), i * core::kPi / 2);
    s.rate = 10.0;
    s.max_range = 4.0;
    s.fov = kFov;
    c.sensors.push_back(s);
  }
  core::ObstacleGroupConfig people;
  people.count = 10;
  people.radius = 0.15;
  people.motion = core::ObstacleMotion::RandomWalk;
  people.speed = 0.6;
  core::ObstacleGroupConfig chairs;
  chairs.count = 2;
  chairs.polygon = true;
  chairs.vertices = { Vec2(-0.2, -0.2), Vec2(0.2, -0.2), Vec2(0.2, 0.2), Vec2(-0.2, 0.2) };
  c.obstacles = { people, chairs };
  return c;
}

/// Distance to the obstacle's nearest point in the cone: a fan of ray entries for a disc (an
/// upper bound within its chord error), the edges one by one for a polygon.
double obstacleDistance(const core::Obstacle& o, const Pose2& sensor, double half_angle)
{
  if (o.shape == core::Obstacle::Shape::Polygon)
  {
    std::vector<core::Segment> edges;
    for (std::size_t i = 0; i < o.vertices.size(); ++i)
    {
      edges.push_back({ o.vertices[i], o.vertices[(i + 1) % o.vertices.size()] });
    }
    return core::coneRangeBruteForce(edges, sensor, half_angle);
  }
  constexpr int kRays = 3000;
  double best = core::kInf;
  for (int i = 0; i <= kRays; ++i)
  {
    const double phi = sensor.theta - half_angle + 2.0 * half_angle * i / kRays;
    best = std::min(best,
                    core::rayCircleDistance(sensor.position(), Vec2(std::cos(phi), std::sin(phi)), o.centre, o.radius));
  }
  return best;
}

struct Counts
{
  int readings = 0;
  int obstacle_hits = 0;
  int shorter_than_ray = 0;
};

void checkReading(const core::Simulation& sim, const core::SimReading& r, Counts* counts)
{
  const core::SensorConfig& s = sim.config().sensors[static_cast<std::size_t>(r.sensor)];
  const double a = 0.5 * s.fov;
  const double wall = core::coneRangeBruteForce(sim.scene().map().grid().segments(), r.sensor_pose, a, s.max_range);
  EXPECT_EQ(r.map_range, wall);
  double nearest = core::kInf;
  int which = -1;
  const auto& obstacles = sim.scene().obstacles();
  for (std::size_t i = 0; i < obstacles.size(); ++i)
  {
    const double d = obstacleDistance(obstacles[i], r.sensor_pose, a);
    if (d < nearest)
    {
      nearest = d;
      which = static_cast<int>(i);
    }
  }
  const double expected = std::min(wall, nearest <= s.max_range ? nearest : core::kInf);
  ++counts->readings;
  if (std::isinf(expected))
  {
    EXPECT_EQ(r.kind, core::SceneHit::Kind::None);
    return;
  }
  EXPECT_NEAR(r.true_range, expected, 1e-4);
  EXPECT_EQ(r.range, r.true_range);  // noise-free
  counts->shorter_than_ray += r.true_range < sim.scene().map().range(r.sensor_pose, s.max_range) - 0.05 ? 1 : 0;
  if (std::abs(wall - nearest) > 1e-3)  // not a tie within the fan's error
  {
    const bool obstacle = nearest < wall;
    EXPECT_EQ(r.kind, obstacle ? core::SceneHit::Kind::Obstacle : core::SceneHit::Kind::Map);
    EXPECT_EQ(r.obstacle, obstacle ? which : -1);
    counts->obstacle_hits += obstacle ? 1 : 0;
  }
}
}  // namespace

TEST(SimulationCones, ReadingsAreTheNearestPointInTheConeWithTheRightLabel)
{
  auto map = std::make_shared<const core::MapRayCaster>(core::loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/"
                                                                                                          "apartment."
                                                                                                          "poly"));
  std::vector<std::string> errors;
  auto sim = core::Simulation::create(coneScenario(), map, &errors);
  ASSERT_NE(sim, nullptr) << (errors.empty() ? "" : errors.front());
  core::StepOutput out;
  Counts counts;
  for (int step = 0; step < 1000; ++step)
  {
    sim->step(&out);
    for (const core::SimReading& r : out.readings)
    {
      checkReading(*sim, r, &counts);
    }
  }
  EXPECT_EQ(counts.readings, 4 * 200);
  EXPECT_GT(counts.obstacle_hits, 10);
  EXPECT_GT(counts.shorter_than_ray, 50);
}
