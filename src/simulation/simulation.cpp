#include "fdml_localization/simulation/simulation.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr double kTimeEpsilon = 1e-9;  // [s]
}  // namespace

Simulation::Simulation(const ScenarioConfig& config, std::shared_ptr<const MapRayCaster> map)
  : config_(config), map_(map), scene_(map), rng_(config.seed), dt_(1.0 / config.step_rate)
{}

std::unique_ptr<Simulation> Simulation::create(const ScenarioConfig& config, std::shared_ptr<const MapRayCaster> map,
                                               std::vector<std::string>* errors)
{
  const std::size_t before = errors->size();
  if (!map || map->map().empty())
  {
    errors->push_back("map_file: the map is empty");
    return nullptr;
  }
  std::unique_ptr<Simulation> sim(new Simulation(config, map));
  sim->checkWaypoints(errors);
  if (sim->placeRobot(errors))
  {
    sim->placeObstacles(errors);
  }
  if (errors->size() != before)
  {
    return nullptr;
  }
  sim->initial_pose_ = sim->true_pose_;
  sim->initial_obstacles_ = sim->obstacles_;
  sim->initial_waypoint_ = sim->robot_waypoint_;
  sim->next_sensor_time_.assign(config.sensors.size(), sim->dt_);
  sim->next_scan_time_ = sim->dt_;
  sim->next_odom_time_ = sim->dt_;
  sim->syncScene();
  return sim;
}

void Simulation::setVelocityCommand(double linear, double angular)
{
  const RobotConfig& r = config_.robot;
  if (!std::isfinite(linear) || !std::isfinite(angular))
  {
    linear = 0.0;
    angular = 0.0;
  }
  command_linear_ = std::clamp(linear, -r.max_linear_speed, r.max_linear_speed);
  command_angular_ = std::clamp(angular, -r.max_angular_speed, r.max_angular_speed);
  command_expiry_ = time_ + r.cmd_vel_timeout;
}

void Simulation::reset()
{
  true_pose_ = initial_pose_;
  odom_pose_ = Pose2();
  obstacles_ = initial_obstacles_;
  robot_waypoint_ = initial_waypoint_;
  robot_waypoints_enabled_ = true;
  linear_velocity_ = 0.0;
  angular_velocity_ = 0.0;
  command_expiry_ = -1.0;
  syncScene();
}

void Simulation::step(StepOutput* out)
{
  out->readings.clear();
  out->has_scan = false;
  out->odometry_due = false;
  ++steps_;
  time_ = static_cast<double>(steps_) * dt_;
  moveObstacles();
  syncScene();
  const Pose2 before = true_pose_;
  moveRobot();
  updateOdometry(before);
  takeReadings(out);
  if (time_ + kTimeEpsilon >= next_odom_time_)
  {
    out->odometry_due = true;
    const double period = config_.odometry.rate > 0.0 ? 1.0 / config_.odometry.rate : dt_;
    next_odom_time_ = std::max(next_odom_time_ + period, time_ + 0.5 * dt_);
  }
}

void Simulation::moveRobot()
{
  const RobotConfig& r = config_.robot;
  linear_velocity_ = 0.0;
  angular_velocity_ = 0.0;
  double turn = 0.0;
  double advance = 0.0;
  bool reached = false;
  if (r.motion == RobotMotion::Rotate || (r.motion == RobotMotion::Waypoints && !robot_waypoints_enabled_))
  {
    turn = r.angular_speed * dt_;
  }
  else if (r.motion == RobotMotion::Waypoints)
  {
    const Vec2 d = r.waypoints[robot_waypoint_] - true_pose_.position();
    const double distance = d.norm();
    const double error = distance > 1e-9 ? angleDiff(std::atan2(d.y(), d.x()), true_pose_.theta) : 0.0;
    const double max_turn = std::abs(r.angular_speed) * dt_;
    if (std::abs(error) > 1e-6)
    {
      turn = std::clamp(error, -max_turn, max_turn);
    }
    else
    {
      advance = std::min(distance, r.linear_speed * dt_);
      reached = distance <= r.linear_speed * dt_;
    }
  }
  else if (time_ <= command_expiry_ + kTimeEpsilon)
  {
    turn = command_angular_ * dt_;
    advance = command_linear_ * dt_;
  }
  const double mid_heading = true_pose_.theta + 0.5 * turn;
  const Vec2 target = true_pose_.position() + advance * Vec2(std::cos(mid_heading), std::sin(mid_heading));
  if (advance != 0.0 && robotFits(target))
  {
    true_pose_.x = target.x();
    true_pose_.y = target.y();
    linear_velocity_ = advance / dt_;
  }
  else
  {
    reached = reached && advance == 0.0;  // blocked: keep aiming at the same waypoint
  }
  if (reached)
  {
    robot_waypoint_ = (robot_waypoint_ + 1) % r.waypoints.size();
  }
  true_pose_.theta = wrapAngle(true_pose_.theta + turn);
  angular_velocity_ = turn / dt_;
}

void Simulation::updateOdometry(const Pose2& before)
{
  Pose2 delta = between(before, true_pose_);
  const OdometryConfig& o = config_.odometry;
  const double travel = std::hypot(delta.x, delta.y);
  if (o.translation_noise > 0.0 && travel > 0.0)
  {
    std::normal_distribution<double> n(0.0, o.translation_noise * std::sqrt(0.5 * travel));
    delta.x += n(rng_);
    delta.y += n(rng_);
  }
  if (o.rotation_noise > 0.0 && delta.theta != 0.0)
  {
    std::normal_distribution<double> n(0.0, o.rotation_noise * std::sqrt(std::abs(delta.theta)));
    delta.theta += n(rng_);
  }
  odom_pose_ = compose(odom_pose_, delta);
}

double Simulation::noisyRange(const SceneHit& hit, double min_range, double max_range, double sigma)
{
  if (hit.kind == SceneHit::Kind::None)
  {
    return kInf;
  }
  if (hit.distance < min_range)
  {
    return -kInf;
  }
  double range = hit.distance;
  if (sigma > 0.0)
  {
    std::normal_distribution<double> n(0.0, sigma);
    range += n(rng_);
  }
  return std::clamp(range, min_range, max_range);
}

SimReading Simulation::readSensor(int index)
{
  const SensorConfig& s = config_.sensors[static_cast<std::size_t>(index)];
  SimReading reading;
  reading.sensor = index;
  reading.time = time_;
  reading.sensor_pose = compose(true_pose_, s.mount);
  // A sensor with a field of view reports the nearest point within its cone (cone_cast.h).
  const SceneHit hit = scene_.castCone(reading.sensor_pose, 0.5 * s.fov, s.max_range);
  reading.kind = hit.kind;
  reading.obstacle = hit.obstacle;
  reading.true_range = hit.distance;
  reading.map_range = hit.map_distance <= s.max_range ? hit.map_distance : kInf;
  reading.range = noisyRange(hit, s.min_range, s.max_range, s.noise_sigma);
  if (s.dropout > 0.0)
  {
    std::uniform_real_distribution<double> u(0.0, 1.0);
    reading.dropped = u(rng_) < s.dropout;
  }
  return reading;
}

void Simulation::takeReadings(StepOutput* out)
{
  for (std::size_t i = 0; i < config_.sensors.size(); ++i)
  {
    if (time_ + kTimeEpsilon >= next_sensor_time_[i])
    {
      out->readings.push_back(readSensor(static_cast<int>(i)));
      next_sensor_time_[i] = std::max(next_sensor_time_[i] + 1.0 / config_.sensors[i].rate, time_ + 0.5 * dt_);
    }
  }
  const ScanConfig& sc = config_.scan;
  if (sc.enabled && time_ + kTimeEpsilon >= next_scan_time_)
  {
    next_scan_time_ = std::max(next_scan_time_ + 1.0 / sc.rate, time_ + 0.5 * dt_);
    out->has_scan = true;
    SimScan& scan = out->scan;
    scan.time = time_;
    scan.sensor_pose = compose(true_pose_, sc.mount);
    scan.ranges.resize(static_cast<std::size_t>(sc.beams));
    scan.kinds.resize(static_cast<std::size_t>(sc.beams));
    for (int b = 0; b < sc.beams; ++b)
    {
      const double angle = -kPi + kTwoPi * b / sc.beams;
      const SceneHit hit = scene_.cast(compose(scan.sensor_pose, Pose2(0.0, 0.0, angle)), sc.max_range);
      scan.ranges[static_cast<std::size_t>(b)] = noisyRange(hit, sc.min_range, sc.max_range, sc.noise_sigma);
      scan.kinds[static_cast<std::size_t>(b)] = hit.kind;
    }
  }
}

}  // namespace core
}  // namespace fdml_localization
