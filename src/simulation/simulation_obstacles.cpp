// Dynamic obstacles of the Simulation: placement, fit tests and motion models.
#include "fdml_localization/simulation/simulation.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kPlacementTries = 5000;
constexpr double kGiveWayTime = 2.0;  // [s] a waypoint obstacle blocked this long turns back

/// Index i moved by delta (+1 or -1) around a loop of n.
std::size_t stepIndex(std::size_t i, int delta, std::size_t n)
{
  return delta > 0 ? (i + 1) % n : (i + n - 1) % n;
}

Vec2 randomDirection(std::mt19937_64* rng)
{
  std::uniform_real_distribution<double> u(-kPi, kPi);
  const double a = u(*rng);
  return Vec2(std::cos(a), std::sin(a));
}

/// Point at arc-length fraction f in [0, 1) along a closed loop of waypoints; sets the next index.
Vec2 pointOnLoop(const std::vector<Vec2>& loop, double f, std::size_t* next)
{
  double total = 0.0;
  for (std::size_t i = 0; i < loop.size(); ++i)
  {
    total += (loop[(i + 1) % loop.size()] - loop[i]).norm();
  }
  double s = f * total;
  for (std::size_t i = 0; i < loop.size(); ++i)
  {
    const Vec2& a = loop[i];
    const Vec2& b = loop[(i + 1) % loop.size()];
    const double len = (b - a).norm();
    if (s <= len && len > 0.0)
    {
      *next = (i + 1) % loop.size();
      return a + (b - a) * (s / len);
    }
    s -= len;
  }
  *next = 1 % loop.size();
  return loop.front();
}
}  // namespace

Obstacle Simulation::obstacleAt(std::size_t index, const Vec2& position) const
{
  if (shapes_[index].empty())
  {
    return Obstacle::disc(position, radii_[index]);
  }
  Ring ring = shapes_[index];
  for (Vec2& v : ring)
  {
    v += position;
  }
  return Obstacle::polygon(ring);
}

bool Simulation::obstacleFits(std::size_t index, const Vec2& position, const Vec2& robot) const
{
  const double gap = config_.clearance;
  const double robot_radius = config_.robot.radius;
  if (shapes_[index].empty())
  {
    const double r = radii_[index];
    return discClearOfWalls(position, r + gap) && (position - robot).norm() >= r + robot_radius + gap;
  }
  const Obstacle o = obstacleAt(index, position);
  const Ring& ring = o.vertices;
  const std::size_t n = ring.size();
  for (const Vec2& v : ring)
  {
    if (!map_->isFree(v))
    {
      return false;
    }
  }
  // No wall crosses or lies inside the polygon (then the polygon is inside free space).
  Box2 box = o.bounds();
  box.extend(box.min - Vec2(gap, gap));
  box.extend(box.max + Vec2(gap, gap));
  bool clear = true;
  const auto& walls = map_->grid().segments();
  map_->grid().forEachSegmentInBox(box, [&](int w) {
    const Segment& wall = walls[static_cast<std::size_t>(w)];
    if (o.contains(wall.a) || o.contains(wall.b))
    {
      clear = false;
    }
    for (std::size_t i = 0; i < n && clear; ++i)
    {
      clear = !segmentsIntersect(wall, Segment{ ring[i], ring[(i + 1) % n] });
    }
    return clear;
  });
  if (!clear || o.contains(robot))
  {
    return false;
  }
  const double min_gap = robot_radius + gap;
  for (std::size_t i = 0; i < n; ++i)
  {
    if (pointSegmentDistanceSquared(robot, Segment{ ring[i], ring[(i + 1) % n] }) < min_gap * min_gap)
    {
      return false;
    }
  }
  return true;
}

bool Simulation::obstacleApart(std::size_t index, const Vec2& p) const
{
  // Obstacles do not start overlapping each other (bounding circles).
  for (std::size_t j = 0; j < index; ++j)
  {
    if ((obstacles_[j].position - p).norm() < radii_[j] + radii_[index] + config_.clearance)
    {
      return false;
    }
  }
  return true;
}

bool Simulation::placeObstacle(std::size_t g, int k, ObstacleState* state, std::string* error)
{
  const ObstacleGroupConfig& group = config_.obstacles[g];
  const std::string path = "obstacles[" + std::to_string(g) + "]";
  const std::size_t index = obstacles_.size();
  const Vec2 robot = true_pose_.position();
  const auto fits = [&](const Vec2& p) { return obstacleFits(index, p, robot) && obstacleApart(index, p); };
  if (!group.positions.empty())
  {
    state->position = group.positions[static_cast<std::size_t>(k)];
    *error = path + ".positions[" + std::to_string(k) + "]: the obstacle does not fit there (wall, robot or another " +
             "obstacle)";
    return fits(state->position);
  }
  if (group.motion == ObstacleMotion::Waypoints)
  {
    for (int t = 0; t < 200; ++t)
    {
      const double f = std::fmod((k + t / 200.0) / group.count, 1.0);
      state->position = pointOnLoop(group.waypoints, f, &state->next_waypoint);
      if (fits(state->position))
      {
        return true;
      }
    }
    *error = path + ".waypoints: no room on the loop for obstacle " + std::to_string(k + 1) + " of " +
             std::to_string(group.count);
    return false;
  }
  const Box2& bounds = map_->map().bounds();
  std::uniform_real_distribution<double> ux(bounds.min.x(), bounds.max.x());
  std::uniform_real_distribution<double> uy(bounds.min.y(), bounds.max.y());
  std::mt19937_64& rng = group_rngs_[g];
  for (int t = 0; t < kPlacementTries; ++t)
  {
    state->position = Vec2(ux(rng), uy(rng));
    if (fits(state->position))
    {
      return true;
    }
  }
  *error = path + ".count: could not place obstacle " + std::to_string(k + 1) + " of " + std::to_string(group.count) +
           " in free space (too many or too large for the map)";
  return false;
}

bool Simulation::placeObstacles(std::vector<std::string>* errors)
{
  const std::size_t before = errors->size();
  for (std::size_t g = 0; g < config_.obstacles.size(); ++g)
  {
    const ObstacleGroupConfig& group = config_.obstacles[g];
    group_rngs_.emplace_back(group.seed != 0 ? group.seed : config_.seed * 1000003ULL + g + 1);
    double bounding = group.radius;
    if (group.polygon)
    {
      bounding = 0.0;
      for (const Vec2& v : group.vertices)
      {
        bounding = std::max(bounding, v.norm());
      }
    }
    for (int k = 0; k < group.count; ++k)
    {
      shapes_.push_back(group.polygon ? group.vertices : Ring());
      radii_.push_back(bounding);
      ObstacleState state;
      state.group = static_cast<int>(g);
      std::string error;
      if (!placeObstacle(g, k, &state, &error))
      {
        errors->push_back(error);
        break;
      }
      if (group.motion == ObstacleMotion::Bounce || group.motion == ObstacleMotion::RandomWalk)
      {
        state.velocity = group.speed * randomDirection(&group_rngs_[g]);
      }
      obstacles_.push_back(state);
    }
  }
  return errors->size() == before;
}

void Simulation::syncScene()
{
  std::vector<Obstacle> geometry;
  geometry.reserve(obstacles_.size());
  for (std::size_t i = 0; i < obstacles_.size(); ++i)
  {
    geometry.push_back(obstacleAt(i, obstacles_[i].position));
  }
  scene_.setObstacles(std::move(geometry));
}

void Simulation::moveObstacles()
{
  for (std::size_t i = 0; i < obstacles_.size(); ++i)
  {
    moveObstacle(i);
  }
}

void Simulation::moveObstacle(std::size_t index)
{
  ObstacleState& o = obstacles_[index];
  const ObstacleGroupConfig& group = config_.obstacles[static_cast<std::size_t>(o.group)];
  switch (group.motion)
  {
    case ObstacleMotion::Static:
      return;
    case ObstacleMotion::Waypoints:
      moveAlongWaypoints(index);
      return;
    case ObstacleMotion::RandomWalk: {
      std::normal_distribution<double> turn(0.0, group.turn_sigma * std::sqrt(dt_));
      const double a = turn(group_rngs_[static_cast<std::size_t>(o.group)]);
      o.velocity = Eigen::Rotation2Dd(a) * o.velocity;
      moveOrReflect(index);
      return;
    }
    case ObstacleMotion::Bounce:
      moveOrReflect(index);
      return;
  }
}

void Simulation::moveAlongWaypoints(std::size_t index)
{
  ObstacleState& o = obstacles_[index];
  const ObstacleGroupConfig& group = config_.obstacles[static_cast<std::size_t>(o.group)];
  const std::size_t n = group.waypoints.size();
  const Vec2 d = group.waypoints[o.next_waypoint] - o.position;
  const double distance = d.norm();
  const double advance = std::min(distance, group.speed * dt_);
  const Vec2 target = distance > 0.0 ? Vec2(o.position + d * (advance / distance)) : o.position;
  if (obstacleFits(index, target, true_pose_.position()))
  {
    o.velocity = (target - o.position) / dt_;
    o.position = target;
    o.blocked_time = 0.0;
    if (distance <= group.speed * dt_)
    {
      o.next_waypoint = stepIndex(o.next_waypoint, o.direction, n);
    }
    return;
  }
  // Blocked by the robot: wait, and after a while turn back along the loop.
  o.velocity = Vec2::Zero();
  o.blocked_time += dt_;
  if (o.blocked_time >= kGiveWayTime)
  {
    o.next_waypoint = stepIndex(o.next_waypoint, -o.direction, n);
    o.direction = -o.direction;
    o.blocked_time = 0.0;
  }
}

void Simulation::moveOrReflect(std::size_t index)
{
  // Bounce and random walk: move on, else reflect off whatever is in the way.
  ObstacleState& o = obstacles_[index];
  const Vec2 v = o.velocity;
  for (const Vec2& candidate : { v, Vec2(-v.x(), v.y()), Vec2(v.x(), -v.y()), Vec2(-v) })
  {
    const Vec2 target = o.position + candidate * dt_;
    if (obstacleFits(index, target, true_pose_.position()))
    {
      o.velocity = candidate;
      o.position = target;
      return;
    }
  }
  const ObstacleGroupConfig& group = config_.obstacles[static_cast<std::size_t>(o.group)];
  o.velocity = group.speed * randomDirection(&group_rngs_[static_cast<std::size_t>(o.group)]);  // stuck: try another
}

}  // namespace core
}  // namespace fdml_localization
