#include "fdml_localization/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
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
  // Homogeneous form: also right for a quaternion that is not normalised.
  const double cosy = q.w * q.w + q.x * q.x - q.y * q.y - q.z * q.z;
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

nav_msgs::OccupancyGrid toOccupancyGrid(const core::MapRayCaster& caster, double resolution, const std::string& frame,
                                        const ros::Time& stamp)
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

core::OccupancyGrid fromOccupancyGridMsg(const nav_msgs::OccupancyGrid& msg)
{
  core::OccupancyGrid grid;
  grid.width = static_cast<int>(std::min<std::uint32_t>(msg.info.width, std::numeric_limits<int>::max()));
  grid.height = static_cast<int>(std::min<std::uint32_t>(msg.info.height, std::numeric_limits<int>::max()));
  grid.resolution = msg.info.resolution;
  grid.origin =
      core::Pose2(msg.info.origin.position.x, msg.info.origin.position.y, quaternionToYaw(msg.info.origin.orientation));
  grid.cells.assign(msg.data.begin(), msg.data.end());
  return grid;
}

nav_msgs::OccupancyGrid toOccupancyGridMsg(const core::OccupancyGrid& grid, const std::string& frame,
                                           const ros::Time& stamp)
{
  nav_msgs::OccupancyGrid msg;
  msg.header.frame_id = frame;
  msg.header.stamp = stamp;
  msg.info.map_load_time = stamp;
  msg.info.resolution = static_cast<float>(grid.resolution);
  msg.info.width = static_cast<std::uint32_t>(std::max(grid.width, 0));
  msg.info.height = static_cast<std::uint32_t>(std::max(grid.height, 0));
  msg.info.origin = toPoseMsg(grid.origin);
  msg.data.assign(grid.cells.begin(), grid.cells.end());
  return msg;
}

// ---------------------------------------------------------------------------------------------
// Localizer node conversions (issue 6): covariance, readings, results, sensor input, rays.
// ---------------------------------------------------------------------------------------------

boost::array<double, 36> toCovariance6(const Eigen::Matrix3d& covariance)
{
  boost::array<double, 36> out;
  out.fill(0.0);
  const int index[3] = { 0, 1, 5 };
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      out[static_cast<std::size_t>(index[r] * 6 + index[c])] = covariance(r, c);
    }
  }
  return out;
}

Eigen::Matrix3d fromCovariance6(const boost::array<double, 36>& covariance)
{
  Eigen::Matrix3d out;
  const int index[3] = { 0, 1, 5 };
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      out(r, c) = covariance[static_cast<std::size_t>(index[r] * 6 + index[c])];
    }
  }
  return out;
}

fdml_localization::Reading toReadingMsg(const core::Reading& reading)
{
  fdml_localization::Reading msg;
  msg.sensor_offset = toPose2D(reading.offset);
  msg.range = reading.range;
  msg.max_range = reading.max_range;
  return msg;
}

core::Reading fromReadingMsg(const fdml_localization::Reading& msg)
{
  core::Reading reading;
  reading.offset = fromPose2D(msg.sensor_offset);
  reading.range = msg.range;
  reading.max_range = msg.max_range;
  return reading;
}

std::vector<core::Reading> fromReadingMsgs(const std::vector<fdml_localization::Reading>& readings)
{
  std::vector<core::Reading> out;
  out.reserve(readings.size());
  for (const auto& msg : readings)
  {
    out.push_back(fromReadingMsg(msg));
  }
  return out;
}

fdml_localization::Candidate toCandidateMsg(const core::Candidate& candidate)
{
  fdml_localization::Candidate msg;
  msg.pose = toPoseMsg(candidate.pose);
  msg.inliers = static_cast<std::uint32_t>(std::max(0, candidate.inliers));
  msg.inlier_mask.assign(candidate.inlier_mask.begin(), candidate.inlier_mask.end());
  msg.rms_residual = candidate.rms_residual;
  return msg;
}

fdml_localization::LocalizationResult toResultMsg(const core::Result& result)
{
  fdml_localization::LocalizationResult msg;
  for (const auto& candidate : result.candidates)
  {
    msg.candidates.push_back(toCandidateMsg(candidate));
  }
  msg.readings_used = static_cast<std::uint32_t>(std::max(0, result.readings_used));
  msg.min_inliers_used = static_cast<std::uint32_t>(std::max(0, result.min_inliers_used));
  msg.engine = core::toString(result.engine);
  msg.method = core::toString(result.method);
  msg.solve_time = result.times.total;
  const std::pair<const char*, double> stages[] = {
    { "table", result.times.table },
    { "preimages", result.times.preimages },
    { "count", result.times.count },
    { "components", result.times.components },
    { "verification", result.times.verification },
    { "polish", result.times.polish },
  };
  for (const auto& stage : stages)
  {
    msg.stage_names.push_back(stage.first);
    msg.stage_times.push_back(stage.second);
  }
  msg.search_truncated = result.truncated;
  return msg;
}

void setDropCounts(const std::map<std::string, std::uint64_t>& drops, fdml_localization::LocalizationResult* msg)
{
  msg->drop_reasons.clear();
  msg->drop_counts.clear();
  for (const auto& entry : drops)
  {
    msg->drop_reasons.push_back(entry.first);
    msg->drop_counts.push_back(static_cast<std::uint32_t>(std::min<std::uint64_t>(entry.second, 0xffffffffu)));
  }
}

namespace
{
/// REP-117 check of one range value; returns nullptr when usable (+inf included).
const char* rangeProblem(double range, double min_range, double max_range)
{
  if (std::isnan(min_range) || std::isnan(max_range) || !(max_range > 0.0) || max_range < min_range)
  {
    return drop_reason::kInvalidLimits;
  }
  if (std::isnan(range))
  {
    return drop_reason::kNanRange;
  }
  if (range == -core::kInf)
  {
    return drop_reason::kNegativeInfinity;
  }
  if (range == core::kInf)
  {
    return nullptr;
  }
  if (range < 0.0)
  {
    return drop_reason::kNegativeRange;
  }
  if (range < min_range)
  {
    return drop_reason::kBelowMinRange;
  }
  if (range > max_range)
  {
    return drop_reason::kAboveMaxRange;
  }
  return nullptr;
}
}  // namespace

bool rangeToReading(const sensor_msgs::Range& msg, double received, TimedReading* reading, std::string* reason)
{
  const char* problem = rangeProblem(msg.range, msg.min_range, msg.max_range);
  if (problem)
  {
    *reason = problem;
    return false;
  }
  reading->frame_id = msg.header.frame_id;
  reading->stamp = static_cast<std::int64_t>(msg.header.stamp.toNSec());
  reading->beam = core::Pose2();
  reading->range = msg.range;
  reading->max_range = msg.max_range;
  reading->received = received;
  return true;
}

std::vector<TimedReading> scanToReadings(const sensor_msgs::LaserScan& msg, int beams, double received,
                                         std::map<std::string, std::uint64_t>* drops)
{
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < msg.ranges.size(); ++i)
  {
    const char* problem = rangeProblem(msg.ranges[i], msg.range_min, msg.range_max);
    if (problem)
    {
      ++(*drops)[problem];
      continue;
    }
    usable.push_back(i);
  }
  std::vector<TimedReading> out;
  if (usable.empty() || beams <= 0)
  {
    return out;
  }
  const std::size_t n = std::min(usable.size(), static_cast<std::size_t>(beams));
  for (std::size_t j = 0; j < n; ++j)
  {
    const std::size_t i = usable[j * usable.size() / n];
    TimedReading reading;
    reading.frame_id = msg.header.frame_id;
    reading.stamp = static_cast<std::int64_t>(msg.header.stamp.toNSec()) +
                    std::llround(static_cast<double>(i) * msg.time_increment * 1e9);
    reading.beam = core::Pose2(0.0, 0.0, core::wrapAngle(msg.angle_min + static_cast<double>(i) * msg.angle_increment));
    reading.range = msg.ranges[i];
    reading.max_range = msg.range_max;
    reading.received = received;
    out.push_back(reading);
  }
  return out;
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
