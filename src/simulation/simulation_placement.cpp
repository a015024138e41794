// The simulation's placement and free-space checks: robot and obstacle starts, waypoints,
// random free poses and kidnapping (the rest of Simulation is in simulation.cpp and
// simulation_obstacles.cpp).
#include "fdml_localization/simulation/simulation.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kRandomPoseTries = 20000;

std::string formatPoint(const Vec2& p)
{
  std::ostringstream out;
  out << "(" << p.x() << ", " << p.y() << ")";
  return out.str();
}
}  // namespace

bool Simulation::discClearOfWalls(const Vec2& centre, double radius) const
{
  if (!map_->isFree(centre))
  {
    return false;
  }
  Box2 box;
  box.extend(centre - Vec2(radius, radius));
  box.extend(centre + Vec2(radius, radius));
  bool clear = true;
  const auto& segments = map_->grid().segments();
  map_->grid().forEachSegmentInBox(box, [&](int i) {
    clear = pointSegmentDistanceSquared(centre, segments[static_cast<std::size_t>(i)]) >= radius * radius;
    return clear;
  });
  return clear;
}

bool Simulation::pathClearOfWalls(const Vec2& a, const Vec2& b, double radius) const
{
  if (!discClearOfWalls(a, radius) || !discClearOfWalls(b, radius))
  {
    return false;
  }
  Box2 box;
  box.extend(a.cwiseMin(b) - Vec2(radius, radius));
  box.extend(a.cwiseMax(b) + Vec2(radius, radius));
  const Segment path{ a, b };
  bool clear = true;
  const auto& segments = map_->grid().segments();
  map_->grid().forEachSegmentInBox(box, [&](int i) {
    const Segment& wall = segments[static_cast<std::size_t>(i)];
    const double r2 = radius * radius;
    clear = !segmentsIntersect(path, wall) && pointSegmentDistanceSquared(wall.a, path) >= r2 &&
            pointSegmentDistanceSquared(wall.b, path) >= r2;
    return clear;
  });
  return clear;
}

bool Simulation::checkWaypoints(std::vector<std::string>* errors) const
{
  const std::size_t before = errors->size();
  auto check_loop = [&](const std::vector<Vec2>& points, double radius, const std::string& path) {
    for (std::size_t i = 0; i < points.size(); ++i)
    {
      const Vec2& a = points[i];
      const Vec2& b = points[(i + 1) % points.size()];
      if (!discClearOfWalls(a, radius))
      {
        errors->push_back(path + "[" + std::to_string(i) + "]: " + formatPoint(a) +
                          " is not in free space with a clearance of " + std::to_string(radius) + " m");
      }
      else if (points.size() > 1 && !pathClearOfWalls(a, b, radius))
      {
        errors->push_back(path + "[" + std::to_string(i) + "]: the path to the next waypoint " + formatPoint(b) +
                          " passes closer than " + std::to_string(radius) + " m to a wall");
      }
    }
  };
  if (config_.robot.motion == RobotMotion::Waypoints)
  {
    check_loop(config_.robot.waypoints, config_.robot.radius + config_.clearance, "robot.waypoints");
  }
  for (std::size_t g = 0; g < config_.obstacles.size(); ++g)
  {
    const ObstacleGroupConfig& group = config_.obstacles[g];
    if (group.motion == ObstacleMotion::Waypoints && !group.polygon)
    {
      check_loop(group.waypoints, group.radius + config_.clearance, "obstacles[" + std::to_string(g) + "].waypoints");
    }
  }
  return errors->size() == before;
}

bool Simulation::randomFreePose(Pose2* pose)
{
  const Box2& b = map_->map().bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x());
  std::uniform_real_distribution<double> uy(b.min.y(), b.max.y());
  std::uniform_real_distribution<double> ut(-kPi, kPi);
  for (int i = 0; i < kRandomPoseTries; ++i)
  {
    const Vec2 p(ux(rng_), uy(rng_));
    if (robotFits(p))
    {
      *pose = Pose2(p.x(), p.y(), ut(rng_));
      return true;
    }
  }
  return false;
}

bool Simulation::placeRobot(std::vector<std::string>* errors)
{
  const RobotConfig& robot = config_.robot;
  if (!robot.random_start)
  {
    if (!robotFits(robot.start.position()))
    {
      errors->push_back("robot.start: " + formatPoint(robot.start.position()) + " is not free for a robot of radius " +
                        std::to_string(robot.radius) + " m");
      return false;
    }
    true_pose_ = robot.start;
  }
  else if (robot.motion == RobotMotion::Waypoints)
  {
    const Vec2 d = robot.waypoints[1] - robot.waypoints[0];
    true_pose_ = Pose2(robot.waypoints[0].x(), robot.waypoints[0].y(), std::atan2(d.y(), d.x()));
  }
  else if (!randomFreePose(&true_pose_))
  {
    errors->push_back("robot.radius: no free start pose found for a robot of radius " + std::to_string(robot.radius) +
                      " m (is the map too small?)");
    return false;
  }
  robot_waypoint_ = robot.motion == RobotMotion::Waypoints && robot.random_start ? 1 : 0;
  return true;
}

bool Simulation::robotFits(const Vec2& p) const
{
  const double radius = config_.robot.radius + config_.clearance;
  if (!discClearOfWalls(p, radius))
  {
    return false;
  }
  for (std::size_t i = 0; i < obstacles_.size(); ++i)
  {
    if (!obstacleFits(i, obstacles_[i].position, p))
    {
      return false;
    }
  }
  return true;
}

bool Simulation::kidnap(const Pose2& pose, std::string* message)
{
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
  {
    *message = "the pose must be finite";
    return false;
  }
  if (!robotFits(pose.position()))
  {
    *message = "pose " + formatPoint(pose.position()) + " is not free for a robot of radius " +
               std::to_string(config_.robot.radius) + " m (wall or obstacle)";
    return false;
  }
  true_pose_ = Pose2(pose.x, pose.y, wrapAngle(pose.theta));
  linear_velocity_ = 0.0;
  angular_velocity_ = 0.0;
  command_expiry_ = -1.0;
  if (config_.robot.motion == RobotMotion::Waypoints)
  {
    // Resume the loop at a waypoint reachable in a straight line, else turn in place.
    robot_waypoints_enabled_ = false;
    const auto& points = config_.robot.waypoints;
    for (std::size_t k = 0; k < points.size() && !robot_waypoints_enabled_; ++k)
    {
      const std::size_t i = (robot_waypoint_ + k) % points.size();
      if (pathClearOfWalls(true_pose_.position(), points[i], config_.robot.radius + config_.clearance))
      {
        robot_waypoint_ = i;
        robot_waypoints_enabled_ = true;
      }
    }
  }
  *message = "kidnapped to " + formatPoint(true_pose_.position());
  return true;
}

bool Simulation::kidnapRandom(Pose2* pose, std::string* message)
{
  Pose2 target;
  if (!randomFreePose(&target))
  {
    *message = "no free pose found";
    return false;
  }
  *pose = target;
  return kidnap(target, message);
}

}  // namespace core
}  // namespace fdml_localization
