#include "fdml_localization/ros/markers.h"

#include "fdml_localization/ros/conversions.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
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

visualization_msgs::MarkerArray obstacleMarkers(const std::vector<core::Obstacle>& obstacles, const std::string& frame,
                                                const ros::Time& stamp, std::size_t previous_count)
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

visualization_msgs::MarkerArray readingMarkers(const std::vector<core::Reading>& readings, const core::Pose2& pose,
                                               const std::vector<bool>& inlier_mask, const std::string& frame_id,
                                               const ros::Time& stamp, double no_return_length)
{
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.header.frame_id = frame_id;
  clear.header.stamp = stamp;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);

  visualization_msgs::Marker rays;
  rays.header = clear.header;
  rays.ns = "rays";
  rays.id = 0;
  rays.type = visualization_msgs::Marker::LINE_LIST;
  rays.action = visualization_msgs::Marker::ADD;
  rays.pose.orientation.w = 1.0;
  rays.scale.x = 0.02;
  visualization_msgs::Marker hits = rays;
  hits.ns = "hits";
  hits.id = 1;
  hits.type = visualization_msgs::Marker::SPHERE_LIST;
  hits.scale.x = hits.scale.y = hits.scale.z = 0.06;

  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const core::Pose2 sensor = core::compose(pose, readings[i].offset);
    const bool no_return = !std::isfinite(readings[i].range);
    const double length = no_return ?
                              std::min(no_return_length, std::isfinite(readings[i].max_range) ? readings[i].max_range :
                                                                                                no_return_length) :
                              readings[i].range;
    const core::Vec2 end = sensor.position() + length * sensor.heading();
    const bool inlier = i >= inlier_mask.size() || inlier_mask[i];
    const std_msgs::ColorRGBA c =
        no_return ? makeColor(0.6f, 0.6f, 0.6f) : (inlier ? makeColor(0.1f, 0.8f, 0.1f) : makeColor(0.9f, 0.1f, 0.1f));
    rays.points.push_back(toPointMsg(sensor.position()));
    rays.points.push_back(toPointMsg(end));
    rays.colors.push_back(c);
    rays.colors.push_back(c);
    if (!no_return)
    {
      hits.points.push_back(toPointMsg(end));
      hits.colors.push_back(c);
    }
  }
  rays.color = makeColor(1.0f, 1.0f, 1.0f);
  hits.color = rays.color;
  array.markers.push_back(rays);
  array.markers.push_back(hits);
  return array;
}

}  // namespace fdml_localization
