#include "fdml_localization/simulation/scenario.h"
#include "fdml_localization/simulation/scenario_readers.h"

#include <cmath>
#include <limits>
#include <set>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr double kMaxRate = 10000.0;  // [Hz]

/// Reads an optional pose {x, y, theta}; true when present and valid.
bool readPose(FieldReader* parent, const std::string& key, Pose2* pose, std::vector<std::string>* errors)
{
  const ParamValue* node = parent->child(key);
  if (node == nullptr)
  {
    return false;
  }
  const std::size_t before = errors->size();
  FieldReader r(*node, parent->pathOf(key), errors);
  r.number("x", &pose->x, -kMaxScenarioCoordinate, kMaxScenarioCoordinate);
  r.number("y", &pose->y, -kMaxScenarioCoordinate, kMaxScenarioCoordinate);
  r.number("theta", &pose->theta, -2.0 * kTwoPi, 2.0 * kTwoPi);
  r.finish();
  pose->theta = wrapAngle(pose->theta);
  return errors->size() == before;
}

void readFrames(FieldReader* root, FramesConfig* frames, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("frames");
  if (node == nullptr)
  {
    return;
  }
  FieldReader r(*node, root->pathOf("frames"), errors);
  r.string("map", &frames->map);
  r.string("odom", &frames->odom);
  r.string("base", &frames->base);
  r.finish();
  for (const std::string* name : { &frames->map, &frames->odom, &frames->base })
  {
    if (name->empty())
    {
      errors->push_back(root->pathOf("frames") + ": frame names must not be empty");
    }
  }
}

void readRobot(FieldReader* root, RobotConfig* robot, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("robot");
  if (node == nullptr)
  {
    return;
  }
  FieldReader r(*node, root->pathOf("robot"), errors);
  r.number("radius", &robot->radius, 1e-3, 5.0);
  if (readPose(&r, "start", &robot->start, errors))
  {
    robot->random_start = false;
  }
  std::string motion = toString(robot->motion);
  if (r.string("motion", &motion, false, { "rotate", "waypoints", "cmd_vel" }))
  {
    robot->motion = motion == "rotate"    ? RobotMotion::Rotate :
                    motion == "waypoints" ? RobotMotion::Waypoints :
                                            RobotMotion::CmdVel;
  }
  r.number("angular_speed", &robot->angular_speed, -20.0, 20.0);
  r.number("linear_speed", &robot->linear_speed, 0.0, 10.0);
  robot->waypoints = readPoints(&r, "waypoints", errors);
  r.number("cmd_vel_timeout", &robot->cmd_vel_timeout, 0.0, 1e3);
  r.number("max_linear_speed", &robot->max_linear_speed, 0.0, 10.0);
  r.number("max_angular_speed", &robot->max_angular_speed, 0.0, 20.0);
  if (robot->motion == RobotMotion::Waypoints)
  {
    if (robot->waypoints.size() < 2)
    {
      r.error("waypoints", "motion 'waypoints' needs at least 2 waypoints");
    }
    if (robot->linear_speed <= 0.0 || robot->angular_speed == 0.0)
    {
      r.error("linear_speed", "motion 'waypoints' needs linear_speed > 0 and angular_speed != 0");
    }
  }
  r.finish();
}

void readSensors(FieldReader* root, std::vector<SensorConfig>* sensors, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("sensors");
  if (node == nullptr)
  {
    return;
  }
  if (!node->isList())
  {
    root->error("sensors", std::string("must be a list of sensors, got ") + ParamValue::typeName(node->type()));
    return;
  }
  std::set<std::string> frames;
  for (std::size_t i = 0; i < node->items().size(); ++i)
  {
    SensorConfig s;
    FieldReader r(node->items()[i], root->pathOf("sensors") + "[" + std::to_string(i) + "]", errors);
    r.string("frame", &s.frame, true);
    if (r.has("frame") && s.frame.empty())
    {
      r.error("frame", "must not be empty");
    }
    else if (!s.frame.empty() && !frames.insert(s.frame).second)
    {
      r.error("frame", "duplicate sensor frame '" + s.frame + "'");
    }
    readPose(&r, "pose", &s.mount, errors);
    r.number("rate", &s.rate, 1e-3, kMaxRate);
    r.number("min_range", &s.min_range, 0.0, 1e4);
    r.number("max_range", &s.max_range, 1e-3, 1e4);
    r.number("fov", &s.fov, 0.0, kPi);
    r.number("noise_sigma", &s.noise_sigma, 0.0, 10.0);
    r.number("dropout", &s.dropout, 0.0, 1.0);
    if (s.min_range >= s.max_range)
    {
      r.error("min_range", "must be below max_range");
    }
    r.finish();
    sensors->push_back(s);
  }
}

void readScan(FieldReader* root, ScanConfig* scan, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("scan");
  if (node == nullptr)
  {
    return;
  }
  FieldReader r(*node, root->pathOf("scan"), errors);
  r.boolean("enabled", &scan->enabled);
  r.string("frame", &scan->frame);
  if (scan->frame.empty())
  {
    r.error("frame", "must not be empty");
  }
  readPose(&r, "pose", &scan->mount, errors);
  std::int64_t beams = scan->beams;
  if (r.integer("beams", &beams, 1, 100000))
  {
    scan->beams = static_cast<int>(beams);
  }
  r.number("rate", &scan->rate, 1e-3, kMaxRate);
  r.number("min_range", &scan->min_range, 0.0, 1e4);
  r.number("max_range", &scan->max_range, 1e-3, 1e4);
  r.number("noise_sigma", &scan->noise_sigma, 0.0, 10.0);
  if (scan->min_range >= scan->max_range)
  {
    r.error("min_range", "must be below max_range");
  }
  r.finish();
}

void readOdometry(FieldReader* root, OdometryConfig* odom, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("odometry");
  if (node == nullptr)
  {
    return;
  }
  FieldReader r(*node, root->pathOf("odometry"), errors);
  r.number("rate", &odom->rate, 0.0, kMaxRate);
  r.number("translation_noise", &odom->translation_noise, 0.0, 10.0);
  r.number("rotation_noise", &odom->rotation_noise, 0.0, 10.0);
  r.finish();
}

void readVisualization(FieldReader* root, VisualizationConfig* vis, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("visualization");
  if (node == nullptr)
  {
    return;
  }
  FieldReader r(*node, root->pathOf("visualization"), errors);
  r.boolean("markers", &vis->markers);
  r.number("marker_rate", &vis->marker_rate, 1e-3, 1000.0);
  r.boolean("occupancy_grid", &vis->occupancy_grid);
  r.number("grid_resolution", &vis->grid_resolution, 1e-3, 10.0);
  r.finish();
}
}  // namespace

const char* toString(RobotMotion motion)
{
  switch (motion)
  {
    case RobotMotion::Rotate:
      return "rotate";
    case RobotMotion::Waypoints:
      return "waypoints";
    case RobotMotion::CmdVel:
      return "cmd_vel";
  }
  return "?";
}

const char* toString(ObstacleMotion motion)
{
  switch (motion)
  {
    case ObstacleMotion::Static:
      return "static";
    case ObstacleMotion::Bounce:
      return "bounce";
    case ObstacleMotion::Waypoints:
      return "waypoints";
    case ObstacleMotion::RandomWalk:
      return "random_walk";
  }
  return "?";
}

std::vector<std::string> parseScenario(const ParamValue& root, ScenarioConfig* config)
{
  std::vector<std::string> errors;
  FieldReader r(root, "", &errors);
  r.string("name", &config->name);
  r.string("map_file", &config->map_file, true);
  if (r.has("map_file") && config->map_file.empty())
  {
    r.error("map_file", "must not be empty");
  }
  std::int64_t seed = static_cast<std::int64_t>(config->seed);
  if (r.integer("seed", &seed, 0, std::numeric_limits<std::int64_t>::max()))
  {
    config->seed = static_cast<std::uint64_t>(seed);
  }
  r.number("step_rate", &config->step_rate, 1.0, kMaxRate);
  r.boolean("publish_clock", &config->publish_clock);
  r.number("time_scale", &config->time_scale, 1e-3, 1000.0);
  r.number("clearance", &config->clearance, 0.0, 1.0);
  readFrames(&r, &config->frames, &errors);
  readRobot(&r, &config->robot, &errors);
  readSensors(&r, &config->sensors, &errors);
  readScan(&r, &config->scan, &errors);
  readOdometry(&r, &config->odometry, &errors);
  readObstacles(&r, &config->obstacles, &errors);
  readVisualization(&r, &config->visualization, &errors);
  r.finish();

  if (config->sensors.empty() && !config->scan.enabled)
  {
    errors.push_back("sensors: at least one sensor (or an enabled scan) is needed");
  }
  if (!config->publish_clock && config->time_scale != 1.0)
  {
    errors.push_back("time_scale: only used with publish_clock: true (wall time runs at 1x), got " +
                     std::to_string(config->time_scale));
  }
  auto check_rate = [&](const std::string& key, double rate) {
    if (rate > config->step_rate)
    {
      errors.push_back(key + ": must not exceed step_rate (" + std::to_string(config->step_rate) + " Hz)");
    }
  };
  check_rate("odometry.rate", config->odometry.rate);
  check_rate("scan.rate", config->scan.rate);
  for (std::size_t i = 0; i < config->sensors.size(); ++i)
  {
    check_rate("sensors[" + std::to_string(i) + "].rate", config->sensors[i].rate);
  }
  for (std::size_t i = 0; i < config->sensors.size(); ++i)
  {
    const std::string& frame = config->sensors[i].frame;
    if (!frame.empty() && (frame == config->frames.base || frame == config->frames.odom ||
                           frame == config->frames.map || (config->scan.enabled && frame == config->scan.frame)))
    {
      errors.push_back("sensors[" + std::to_string(i) + "].frame: '" + frame + "' is already used by another frame");
    }
  }
  return errors;
}

}  // namespace core
}  // namespace fdml_localization
