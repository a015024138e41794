#include "fdml_localization/ros/conversions.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
// ---------------------------------------------------------------------------------------------
// Localizer node conversions.
// ---------------------------------------------------------------------------------------------

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
  if ((siny == 0.0 && cosy == 0.0) || !std::isfinite(siny) || !std::isfinite(cosy))
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
  return core::Pose2(pose.x, pose.y, pose.theta);
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
    { "table", result.times.table },           { "preimages", result.times.preimages },
    { "count", result.times.count },           { "components", result.times.components },
    { "verification", result.times.verification }, { "polish", result.times.polish },
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

namespace
{
std_msgs::ColorRGBA color(float r, float g, float b, float a = 1.0f)
{
  std_msgs::ColorRGBA c;
  c.r = r;
  c.g = g;
  c.b = b;
  c.a = a;
  return c;
}

geometry_msgs::Point point(const core::Vec2& p)
{
  geometry_msgs::Point out;
  out.x = p.x();
  out.y = p.y();
  out.z = 0.0;
  return out;
}
}  // namespace

visualization_msgs::Marker mapMarker(const core::PolygonMap& map, const std::string& frame_id)
{
  visualization_msgs::Marker marker;
  marker.header.frame_id = frame_id;
  marker.ns = "map";
  marker.id = 0;
  marker.type = visualization_msgs::Marker::LINE_LIST;
  marker.action = visualization_msgs::Marker::ADD;
  marker.pose.orientation.w = 1.0;
  marker.scale.x = 0.03;
  marker.color = color(0.1f, 0.1f, 0.1f);
  for (const core::Segment& edge : map.edges())
  {
    marker.points.push_back(point(edge.a));
    marker.points.push_back(point(edge.b));
  }
  return marker;
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
    const double length =
        no_return ? std::min(no_return_length, std::isfinite(readings[i].max_range) ? readings[i].max_range : no_return_length)
                  : readings[i].range;
    const core::Vec2 end = sensor.position() + length * sensor.heading();
    const bool inlier = i >= inlier_mask.size() || inlier_mask[i];
    const std_msgs::ColorRGBA c =
        no_return ? color(0.6f, 0.6f, 0.6f) : (inlier ? color(0.1f, 0.8f, 0.1f) : color(0.9f, 0.1f, 0.1f));
    rays.points.push_back(point(sensor.position()));
    rays.points.push_back(point(end));
    rays.colors.push_back(c);
    rays.colors.push_back(c);
    if (!no_return)
    {
      hits.points.push_back(point(end));
      hits.colors.push_back(c);
    }
  }
  rays.color = color(1.0f, 1.0f, 1.0f);
  hits.color = rays.color;
  array.markers.push_back(rays);
  array.markers.push_back(hits);
  return array;
}

}  // namespace fdml_localization
