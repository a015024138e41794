#include "fdml_localization/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fdml_localization
{
geometry_msgs::Pose2D toPose2D(const core::Pose2& pose)
{
  geometry_msgs::Pose2D msg;
  msg.x = pose.x;
  msg.y = pose.y;
  msg.theta = pose.theta;
  return msg;
}

core::Pose2 fromPose2D(const geometry_msgs::Pose2D& pose)
{
  return core::Pose2(pose.x, pose.y, core::wrapAngle(pose.theta));
}

geometry_msgs::Quaternion yawToQuaternion(double yaw)
{
  geometry_msgs::Quaternion q;
  q.x = 0.0;
  q.y = 0.0;
  q.z = std::sin(0.5 * yaw);
  q.w = std::cos(0.5 * yaw);
  return q;
}

double quaternionToYaw(const geometry_msgs::Quaternion& q)
{
  const double siny = 2.0 * (q.w * q.z + q.x * q.y);
  const double cosy = 1.0 - 2.0 * (q.y * q.y + q.z * q.z);
  if (!std::isfinite(siny) || !std::isfinite(cosy) || (siny == 0.0 && cosy == 0.0))
  {
    return 0.0;
  }
  return core::wrapAngle(std::atan2(siny, cosy));
}

geometry_msgs::Pose toPoseMsg(const core::Pose2& pose)
{
  geometry_msgs::Pose msg;
  msg.position.x = pose.x;
  msg.position.y = pose.y;
  msg.position.z = 0.0;
  msg.orientation = yawToQuaternion(pose.theta);
  return msg;
}

core::Pose2 fromPoseMsg(const geometry_msgs::Pose& pose)
{
  return core::Pose2(pose.position.x, pose.position.y, quaternionToYaw(pose.orientation));
}

geometry_msgs::Transform toTransformMsg(const core::Pose2& pose)
{
  geometry_msgs::Transform msg;
  msg.translation.x = pose.x;
  msg.translation.y = pose.y;
  msg.translation.z = 0.0;
  msg.rotation = yawToQuaternion(pose.theta);
  return msg;
}

core::Pose2 fromTransformMsg(const geometry_msgs::Transform& transform)
{
  return core::Pose2(transform.translation.x, transform.translation.y, quaternionToYaw(transform.rotation));
}

geometry_msgs::Point toPointMsg(const core::Vec2& p, double z)
{
  geometry_msgs::Point msg;
  msg.x = p.x();
  msg.y = p.y();
  msg.z = z;
  return msg;
}

std_msgs::ColorRGBA makeColor(float r, float g, float b, float a)
{
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

visualization_msgs::MarkerArray mapMarkers(const core::PolygonMap& map, const std::string& frame,
                                           const ros::Time& stamp)
{
  visualization_msgs::Marker walls;
  walls.header.frame_id = frame;
  walls.header.stamp = stamp;
  walls.ns = "map_walls";
  walls.id = 0;
  walls.type = visualization_msgs::Marker::LINE_LIST;
  walls.action = visualization_msgs::Marker::ADD;
  walls.pose.orientation.w = 1.0;
  walls.scale.x = 0.03;
  walls.color = makeColor(0.1f, 0.1f, 0.1f);
  for (const core::Segment& e : map.edges())
  {
    walls.points.push_back(toPointMsg(e.a));
    walls.points.push_back(toPointMsg(e.b));
  }
  visualization_msgs::MarkerArray array;
  array.markers.push_back(walls);
  return array;
}

visualization_msgs::MarkerArray obstacleMarkers(const std::vector<core::Obstacle>& obstacles,
                                                const std::string& frame, const ros::Time& stamp,
                                                std::size_t previous_count)
{
  visualization_msgs::MarkerArray array;
  for (std::size_t i = 0; i < std::max(obstacles.size(), previous_count); ++i)
  {
    visualization_msgs::Marker m;
    m.header.frame_id = frame;
    m.header.stamp = stamp;
    m.ns = "obstacles";
    m.id = static_cast<int>(i);
    m.pose.orientation.w = 1.0;
    if (i >= obstacles.size())
    {
      m.action = visualization_msgs::Marker::DELETE;
      array.markers.push_back(m);
      continue;
    }
    const core::Obstacle& o = obstacles[i];
    m.action = visualization_msgs::Marker::ADD;
    m.color = makeColor(0.85f, 0.35f, 0.1f, 0.9f);
    if (o.shape == core::Obstacle::Shape::Disc)
    {
      m.type = visualization_msgs::Marker::CYLINDER;
      m.pose.position = toPointMsg(o.centre, 0.25);
      m.scale.x = 2.0 * o.radius;
      m.scale.y = 2.0 * o.radius;
      m.scale.z = 0.5;
    }
    else
    {
      m.type = visualization_msgs::Marker::LINE_STRIP;
      m.scale.x = 0.03;
      for (const core::Vec2& v : o.vertices)
      {
        m.points.push_back(toPointMsg(v));
      }
      m.points.push_back(toPointMsg(o.vertices.front()));
    }
    array.markers.push_back(m);
  }
  return array;
}

nav_msgs::OccupancyGrid toOccupancyGrid(const core::MapRayCaster& caster, double resolution,
                                        const std::string& frame, const ros::Time& stamp)
{
  if (!(resolution > 0.0))
  {
    throw std::invalid_argument("occupancy grid resolution must be > 0");
  }
  const core::Box2& bounds = caster.map().bounds();
  // A margin of two cells, so the outer walls are surrounded by unknown cells.
  const core::Vec2 origin = bounds.min - core::Vec2(2.0 * resolution, 2.0 * resolution);
  const int width = static_cast<int>(std::ceil(bounds.size().x() / resolution)) + 4;
  const int height = static_cast<int>(std::ceil(bounds.size().y() / resolution)) + 4;
  nav_msgs::OccupancyGrid grid;
  grid.header.frame_id = frame;
  grid.header.stamp = stamp;
  grid.info.map_load_time = stamp;
  grid.info.resolution = static_cast<float>(resolution);
  grid.info.width = static_cast<std::uint32_t>(width);
  grid.info.height = static_cast<std::uint32_t>(height);
  grid.info.origin.position = toPointMsg(origin);
  grid.info.origin.orientation.w = 1.0;
  grid.data.resize(static_cast<std::size_t>(width) * static_cast<std::size_t>(height));
  const core::Ring& outer = caster.map().outer();
  for (int row = 0; row < height; ++row)
  {
    for (int col = 0; col < width; ++col)
    {
      core::Box2 cell;
      cell.extend(origin + core::Vec2(col * resolution, row * resolution));
      cell.extend(origin + core::Vec2((col + 1) * resolution, (row + 1) * resolution));
      const core::Vec2 centre = origin + core::Vec2((col + 0.5) * resolution, (row + 0.5) * resolution);
      std::int8_t value = 0;
      if (caster.grid().anySegmentInBox(cell))
      {
        value = 100;
      }
      else if (!caster.isFree(centre))
      {
        value = core::pointInRing(centre, outer) ? 100 : -1;
      }
      grid.data[static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + static_cast<std::size_t>(col)] =
          value;
    }
  }
  return grid;
}

}  // namespace fdml_localization
