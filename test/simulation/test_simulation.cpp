// Tests of the ROS-free simulator core: scenario parsing and validation, obstacle and robot
// motion invariants (brute force over every map edge), odometry, kidnapping, sensor models.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/simulation.h"

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace core = fdml_localization::core;
using core::Vec2;

namespace
{
core::ParamValue fromYaml(const YAML::Node& node)
{
  switch (node.Type())
  {
    case YAML::NodeType::Map: {
      core::ParamValue v = core::ParamValue::makeMap();
      for (const auto& kv : node)
      {
        v.set(kv.first.as<std::string>(), fromYaml(kv.second));
      }
      return v;
    }
    case YAML::NodeType::Sequence: {
      core::ParamValue v = core::ParamValue::makeList();
      for (const auto& item : node)
      {
        v.append(fromYaml(item));
      }
      return v;
    }
    case YAML::NodeType::Scalar: {
      const std::string text = node.Scalar();
      long long i = 0;
      double d = 0.0;
      bool b = false;
      if (node.Tag() != "!" && YAML::convert<long long>::decode(node, i))
      {
        return core::ParamValue::fromInt(i);
      }
      if (node.Tag() != "!" && YAML::convert<double>::decode(node, d))
      {
        return core::ParamValue::fromDouble(d);
      }
      if (node.Tag() != "!" && YAML::convert<bool>::decode(node, b))
      {
        return core::ParamValue::fromBool(b);
      }
      return core::ParamValue::fromString(text);
    }
    default:
      return core::ParamValue();
  }
}

core::ParamValue parseYaml(const std::string& text)
{
  return fromYaml(YAML::Load(text));
}

/// Parses a scenario, asserting nothing: returns the errors.
std::vector<std::string> parse(const std::string& text, core::ScenarioConfig* config)
{
  return core::parseScenario(parseYaml(text), config);
}

bool anyErrorStartsWith(const std::vector<std::string>& errors, const std::string& prefix)
{
  return std::any_of(errors.begin(), errors.end(), [&prefix](const std::string& e) { return e.rfind(prefix, 0) == 0; });
}

std::string joined(const std::vector<std::string>& errors)
{
  std::string out;
  for (const auto& e : errors)
  {
    out += e + "\n";
  }
  return out;
}

/// A 4 x 3 m room with a 1 x 0.6 m pillar in the middle.
std::shared_ptr<const core::MapRayCaster> roomWithPillar()
{
  std::vector<core::Ring> rings = { { Vec2(0, 0), Vec2(4, 0), Vec2(4, 3), Vec2(0, 3) },
                                    { Vec2(1.5, 1.2), Vec2(2.5, 1.2), Vec2(2.5, 1.8), Vec2(1.5, 1.8) } };
  return std::make_shared<core::MapRayCaster>(core::PolygonMap::fromRings(rings, "pillar_room"));
}

const char* kBaseScenario = R"(
map_file: /nonexistent/room.poly
seed: 3
step_rate: 50
robot: {radius: 0.2, start: {x: 0.5, y: 0.5, theta: 0.0}, motion: rotate, angular_speed: 1.0}
sensors:
  - {frame: range_front, pose: {x: 0.1, y: 0.0, theta: 0.0}, rate: 10, max_range: 6.0}
)";

/// Minimum distance from p to every edge of the map, by brute force.
double wallDistance(const core::PolygonMap& map, const Vec2& p)
{
  double best = core::kInf;
  for (const auto& e : map.edges())
  {
    best = std::min(best, std::sqrt(core::pointSegmentDistanceSquared(p, e)));
  }
  return best;
}
}  // namespace

TEST(ScenarioParsing, FullScenarioIsRead)
{
  core::ScenarioConfig c;
  const auto errors = parse(R"(
name: test
map_file: package://fdml_localization/maps/square_room.poly
seed: 42
step_rate: 200
publish_clock: true
time_scale: 5
clearance: 0.02
frames: {map: world, odom: odom2, base: base}
robot:
  radius: 0.25
  motion: waypoints
  linear_speed: 0.4
  angular_speed: 1.5
  waypoints: [[0.5, 0.5], [1.5, 0.5], [1.5, 1.5]]
sensors:
  - {frame: s0, pose: {x: 0.1, y: 0.2, theta: 1.5}, rate: 20, min_range: 0.05, max_range: 3,
     fov: 0.1, noise_sigma: 0.01, dropout: 0.1}
  - {frame: s1}
scan: {enabled: true, frame: laser, beams: 12, rate: 4, max_range: 10}
odometry: {rate: 25, translation_noise: 0.05, rotation_noise: 0.02}
obstacles:
  - {count: 3, shape: disc, radius: 0.2, motion: random_walk, speed: 0.3, turn_sigma: 2, seed: 9}
  - {count: 1, shape: polygon, vertices: [[-0.1, -0.1], [0.1, -0.1], [0.0, 0.1]], motion: bounce}
visualization: {markers: false, marker_rate: 5, occupancy_grid: true, grid_resolution: 0.1}
)",
                            &c);
  ASSERT_TRUE(errors.empty()) << joined(errors);
  EXPECT_EQ(c.seed, 42u);
  EXPECT_DOUBLE_EQ(c.step_rate, 200.0);
  EXPECT_TRUE(c.publish_clock);
  EXPECT_DOUBLE_EQ(c.time_scale, 5.0);
  EXPECT_EQ(c.frames.map, "world");
  EXPECT_EQ(c.frames.base, "base");
  EXPECT_EQ(c.robot.motion, core::RobotMotion::Waypoints);
  EXPECT_TRUE(c.robot.random_start);
  ASSERT_EQ(c.robot.waypoints.size(), 3u);
  EXPECT_DOUBLE_EQ(c.robot.waypoints[2].y(), 1.5);
  ASSERT_EQ(c.sensors.size(), 2u);
  EXPECT_EQ(c.sensors[0].frame, "s0");
  EXPECT_DOUBLE_EQ(c.sensors[0].mount.y, 0.2);
  EXPECT_DOUBLE_EQ(c.sensors[0].mount.theta, 1.5);
  EXPECT_DOUBLE_EQ(c.sensors[0].dropout, 0.1);
  EXPECT_DOUBLE_EQ(c.sensors[1].max_range, core::SensorConfig().max_range);
  EXPECT_TRUE(c.scan.enabled);
  EXPECT_EQ(c.scan.beams, 12);
  EXPECT_DOUBLE_EQ(c.odometry.translation_noise, 0.05);
  ASSERT_EQ(c.obstacles.size(), 2u);
  EXPECT_EQ(c.obstacles[0].motion, core::ObstacleMotion::RandomWalk);
  EXPECT_EQ(c.obstacles[0].seed, 9u);
  EXPECT_TRUE(c.obstacles[1].polygon);
  EXPECT_EQ(c.obstacles[1].vertices.size(), 3u);
  EXPECT_TRUE(c.visualization.occupancy_grid);
  EXPECT_DOUBLE_EQ(c.visualization.grid_resolution, 0.1);
}

TEST(ScenarioParsing, EveryProblemIsReportedWithItsKey)
{
  core::ScenarioConfig c;
  const auto errors = parse(R"(
seed: 1
colour: red
robot: {radius: -1, motion: fly, wheels: 4}
sensors:
  - {pose: {x: 0.1}, rate: 10}
  - {frame: a, max_range: 1.0, min_range: 2.0, dropout: 1.5}
  - {frame: a, noise_sigma: "big"}
obstacles:
  - {count: 2, shape: polygon, vertices: [[0, 0], [1, 1]], motion: waypoints}
  - {count: 2, positions: [[0, 0]]}
)",
                            &c);
  EXPECT_TRUE(anyErrorStartsWith(errors, "map_file: required")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "colour: unknown key")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "robot.radius: must be in")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "robot.motion: must be one of")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "robot.wheels: unknown key")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "sensors[0].frame: required")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "sensors[1].min_range: must be below")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "sensors[1].dropout: must be in [0, 1]")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "sensors[2].frame: duplicate")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "sensors[2].noise_sigma: must be a number")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "obstacles[0].vertices: a polygon obstacle")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "obstacles[0].waypoints: motion 'waypoints' needs")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "obstacles[1].positions: has 1 points")) << joined(errors);
  EXPECT_EQ(errors.size(), 13u) << joined(errors);
}

TEST(ScenarioParsing, RatesAboveTheStepRateAreRejected)
{
  core::ScenarioConfig c;
  const auto errors = parse(R"(
map_file: x.poly
step_rate: 20
sensors: [{frame: s, rate: 50}]
odometry: {rate: 100}
)",
                            &c);
  EXPECT_TRUE(anyErrorStartsWith(errors, "sensors[0].rate: must not exceed step_rate")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "odometry.rate: must not exceed step_rate")) << joined(errors);
}

TEST(ScenarioParsing, TimeScaleNeedsTheClock)
{
  core::ScenarioConfig c;
  auto errors = parse("{map_file: x.poly, time_scale: 4.0, sensors: [{frame: s}]}", &c);
  EXPECT_TRUE(anyErrorStartsWith(errors, "time_scale: only used with publish_clock")) << joined(errors);
  errors = parse("{map_file: x.poly, time_scale: 4.0, publish_clock: true, sensors: [{frame: s}]}", &c);
  EXPECT_TRUE(errors.empty()) << joined(errors);
}

TEST(ScenarioParsing, ShippedScenariosAreValid)
{
  // Every file in config/scenarios/ (at least the eight shipped ones).
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(FDML_SOURCE_DIR) + "/config/scenarios"))
  {
    if (entry.path().extension() != ".yaml")
    {
      continue;
    }
    ++files;
    SCOPED_TRACE(entry.path().filename().string());
    core::ScenarioConfig c;
    const auto errors = core::parseScenario(fromYaml(YAML::LoadFile(entry.path().string())), &c);
    ASSERT_TRUE(errors.empty()) << joined(errors);
    const std::string prefix = "package://fdml_localization/";
    ASSERT_EQ(c.map_file.rfind(prefix, 0), 0u);
    const std::string map_path = std::string(FDML_SOURCE_DIR) + "/" + c.map_file.substr(prefix.size());
    auto map = std::make_shared<core::MapRayCaster>(core::loadPolyFile(map_path));
    std::vector<std::string> sim_errors;
    EXPECT_NE(core::Simulation::create(c, map, &sim_errors), nullptr) << joined(sim_errors);
  }
  EXPECT_GE(files, 8);
}

TEST(SimulationCreate, ObstaclesThatDoNotFitAreNamed)
{
  core::ScenarioConfig c;
  ASSERT_TRUE(parse(std::string(kBaseScenario) + R"(
obstacles:
  - {count: 500, radius: 0.4, motion: static}
)",
                    &c)
                  .empty());
  std::vector<std::string> errors;
  EXPECT_EQ(core::Simulation::create(c, roomWithPillar(), &errors), nullptr);
  EXPECT_TRUE(anyErrorStartsWith(errors, "obstacles[0].count: could not place obstacle")) << joined(errors);

  core::ScenarioConfig d;
  ASSERT_TRUE(parse(std::string(kBaseScenario) + R"(
obstacles:
  - {count: 3, radius: 0.1, positions: [[3.5, 2.5], [2.0, 1.5], [0.6, 0.6]]}
  - {count: 1, radius: 0.1, motion: waypoints, waypoints: [[0.5, 2.5], [3.5, 2.5], [3.5, 0.5]]}
)",
                    &d)
                  .empty());
  errors.clear();
  EXPECT_EQ(core::Simulation::create(d, roomWithPillar(), &errors), nullptr);
  // [2.0, 1.5] is inside the pillar, [0.6, 0.6] overlaps the robot at (0.5, 0.5).
  EXPECT_TRUE(anyErrorStartsWith(errors, "obstacles[0].positions[1]")) << joined(errors);
  EXPECT_TRUE(anyErrorStartsWith(errors, "obstacles[1].waypoints[2]: the path")) << joined(errors);
}

TEST(SimulationCreate, RobotStartInAWallIsNamed)
{
  core::ScenarioConfig c;
  ASSERT_TRUE(parse(R"(
map_file: x.poly
robot: {start: {x: 2.0, y: 1.5}}
sensors: [{frame: s}]
)",
                    &c)
                  .empty());
  std::vector<std::string> errors;
  EXPECT_EQ(core::Simulation::create(c, roomWithPillar(), &errors), nullptr);
  EXPECT_TRUE(anyErrorStartsWith(errors, "robot.start")) << joined(errors);
}

/// An obstacle lies in free space (brute force over every map edge) and off the robot disc.
::testing::AssertionResult obstacleInFreeSpace(const core::PolygonMap& pm, const core::Obstacle& o, const Vec2& robot,
                                               double robot_radius)
{
  if (o.shape == core::Obstacle::Shape::Disc)
  {
    if (!pm.containsBruteForce(o.centre) || wallDistance(pm, o.centre) < o.radius - 1e-9)
    {
      return ::testing::AssertionFailure() << "disc at " << o.centre.transpose() << " not in free space";
    }
    if ((o.centre - robot).norm() < o.radius + robot_radius - 1e-9)
    {
      return ::testing::AssertionFailure() << "disc at " << o.centre.transpose() << " overlaps the robot";
    }
    return ::testing::AssertionSuccess();
  }
  const std::size_t n = o.vertices.size();
  if (o.contains(robot))
  {
    return ::testing::AssertionFailure() << "polygon contains the robot";
  }
  for (std::size_t k = 0; k < n; ++k)
  {
    const core::Segment edge{ o.vertices[k], o.vertices[(k + 1) % n] };
    if (!pm.containsBruteForce(edge.a) ||
        std::sqrt(core::pointSegmentDistanceSquared(robot, edge)) < robot_radius - 1e-9)
    {
      return ::testing::AssertionFailure() << "polygon vertex " << k << " outside the map or on the robot";
    }
    for (const auto& wall : pm.edges())
    {
      if (core::segmentsIntersect(edge, wall))
      {
        return ::testing::AssertionFailure() << "polygon edge " << k << " crosses a wall";
      }
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(SimulationMotion, ObstaclesStayInFreeSpaceAndOffTheRobotFor10000Steps)
{
  core::ScenarioConfig c;
  const auto parse_errors = parse(R"(
map_file: x.poly
seed: 11
step_rate: 20
clearance: 0.0
robot: {radius: 0.2, motion: waypoints, linear_speed: 0.5, angular_speed: 2.0,
        waypoints: [[0.5, 0.5], [3.5, 0.5], [3.5, 2.5], [0.5, 2.5]]}
sensors: [{frame: s, rate: 5}]
obstacles:
  - {count: 6, radius: 0.15, motion: bounce, speed: 1.0}
  - {count: 6, radius: 0.1, motion: random_walk, speed: 0.8, turn_sigma: 3.0}
  - {count: 3, radius: 0.2, motion: waypoints, speed: 0.7,
     waypoints: [[3.5, 2.5], [3.5, 0.5], [0.5, 0.5], [0.5, 2.5]]}
  - {count: 2, shape: polygon, vertices: [[-0.2, -0.1], [0.2, -0.1], [0.0, 0.2]], motion: bounce, speed: 0.6}
)",
                                  &c);
  ASSERT_TRUE(parse_errors.empty()) << joined(parse_errors);
  auto map = roomWithPillar();
  std::vector<std::string> errors;
  auto sim = core::Simulation::create(c, map, &errors);
  ASSERT_NE(sim, nullptr) << joined(errors);
  const core::PolygonMap& pm = map->map();
  const double robot_radius = c.robot.radius;
  std::vector<Vec2> start;
  for (const auto& o : sim->obstacleStates())
  {
    start.push_back(o.position);
  }
  double robot_travel = 0.0;
  core::StepOutput out;
  for (int step = 0; step < 10000; ++step)
  {
    const Vec2 robot_before = sim->truePose().position();
    sim->step(&out);
    const Vec2 robot = sim->truePose().position();
    robot_travel += (robot - robot_before).norm();
    ASSERT_TRUE(pm.containsBruteForce(robot)) << "step " << step;
    ASSERT_GE(wallDistance(pm, robot), robot_radius - 1e-9) << "step " << step;
    const auto& obstacles = sim->scene().obstacles();
    ASSERT_EQ(obstacles.size(), 17u);
    for (std::size_t i = 0; i < obstacles.size(); ++i)
    {
      ASSERT_TRUE(obstacleInFreeSpace(pm, obstacles[i], robot, robot_radius)) << "step " << step << " obstacle " << i;
    }
  }
  // The test is not vacuous: everything that should move did move.
  EXPECT_GT(robot_travel, 100.0);
  for (std::size_t i = 0; i < start.size(); ++i)
  {
    EXPECT_GT((sim->obstacleStates()[i].position - start[i]).norm(), 1e-3) << "obstacle " << i;
  }
}
