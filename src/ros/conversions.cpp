#include "fdml_localization/ros/conversions.h"

#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/ranking.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace fdml_localization
{
ros::Time stampToTime(std::int64_t stamp)
{
  ros::Time time;
  time.fromNSec(static_cast<std::uint64_t>(std::max<std::int64_t>(stamp, 0)));
  return time;
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

bool fieldOfViewToHalfAngle(double field_of_view, double* half_angle)
{
  // float32 rounds pi up by 9e-8 rad: accept that much above pi.
  constexpr double kFloatSlack = 1e-6;
  if (!(field_of_view >= 0.0 && field_of_view <= core::kPi + kFloatSlack))
  {
    return false;
  }
  *half_angle = std::min(0.5 * field_of_view, core::kMaxConeHalfAngle);
  return true;
}

fdml_localization::Reading toReadingMsg(const core::Reading& reading)
{
  fdml_localization::Reading msg;
  msg.sensor_offset = toPose2D(reading.offset);
  msg.range = reading.range;
  msg.max_range = reading.max_range;
  msg.field_of_view = 2.0 * reading.half_angle;
  return msg;
}

core::Reading fromReadingMsg(const fdml_localization::Reading& msg)
{
  core::Reading reading;
  reading.offset = fromPose2D(msg.sensor_offset);
  reading.range = msg.range;
  reading.max_range = msg.max_range;
  if (!fieldOfViewToHalfAngle(msg.field_of_view, &reading.half_angle))
  {
    std::ostringstream error;
    error << "field_of_view: " << msg.field_of_view << " rad must be finite and in [0, pi] (0 = a ray)";
    throw std::invalid_argument(error.str());
  }
  return reading;
}

std::vector<core::Reading> fromReadingMsgs(const std::vector<fdml_localization::Reading>& readings)
{
  std::vector<core::Reading> out;
  out.reserve(readings.size());
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    try
    {
      out.push_back(fromReadingMsg(readings[i]));
    }
    catch (const std::invalid_argument& e)
    {
      throw std::invalid_argument("readings[" + std::to_string(i) + "]." + e.what());
    }
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
  msg.certificate_max_consensus = result.certificate.max_consensus_bound;
  msg.certificate_best_consensus = result.certificate.best_consensus;
  msg.certificate_complete = result.certificate.complete;
  msg.unambiguous = core::isUnambiguous(result);
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

}  // namespace fdml_localization
