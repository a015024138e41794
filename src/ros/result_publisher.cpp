#include "fdml_localization/ros/result_publisher.h"

#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/markers.h"

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
core::Pose2 carryForward(const core::Pose2& pose, const core::Pose2& base_first, const core::Pose2& base_newest)
{
  return core::compose(pose, core::between(base_first, base_newest));
}

Eigen::Matrix3d carryForwardCovariance(const Eigen::Matrix3d& covariance, const core::Pose2& pose,
                                       const core::Pose2& base_first, const core::Pose2& base_newest)
{
  // q' = q (+) d with d fixed: dq'/dq = [1 0 -s dx - c dy; 0 1 c dx - s dy; 0 0 1].
  const core::Pose2 d = core::between(base_first, base_newest);
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();
  jacobian(0, 2) = -s * d.x - c * d.y;
  jacobian(1, 2) = c * d.x - s * d.y;
  return jacobian * covariance * jacobian.transpose();
}

ResultPublisher::ResultPublisher(ros::NodeHandle& nh, ros::NodeHandle& private_nh, const Params& params)
  : params_(params)
{
  status_pub_ = private_nh.advertise<fdml_localization::Status>("status", 10, true);
  if (params_.publish_initialpose)
  {
    initialpose_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("initialpose", 1, false);
  }
  candidates_pub_ = private_nh.advertise<geometry_msgs::PoseArray>("candidates", 1, true);
  result_pub_ = private_nh.advertise<fdml_localization::LocalizationResult>("result", 1, true);
  pose_pub_ = private_nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 1, true);
  map_markers_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>("map_markers", 1, true);
  reading_markers_pub_ = private_nh.advertise<visualization_msgs::MarkerArray>("reading_markers", 1, true);
}

void ResultPublisher::publishBatch(const Job& job, const core::Result& result, const Outcome& outcome, bool unambiguous,
                                   const core::MapRayCaster& map)
{
  const Batch& batch = job.batch;
  const ros::Time stamp = stampToTime(batch.newest_stamp);
  result_pub_.publish(outcome.result);

  geometry_msgs::PoseArray candidates;
  candidates.header.stamp = stamp;
  candidates.header.frame_id = params_.global_frame_id;
  for (const core::Candidate& candidate : result.candidates)
  {
    candidates.poses.push_back(toPoseMsg(carryForward(candidate.pose, batch.base_first, batch.base_newest)));
  }
  candidates_pub_.publish(candidates);
  if (result.candidates.empty())
  {
    return;
  }
  const core::Candidate& best = result.candidates.front();
  reading_markers_pub_.publish(
      readingMarkers(job.readings, best.pose, best.inlier_mask, params_.global_frame_id, stamp));
  if (unambiguous)
  {
    pose_pub_.publish(poseMessage(job, best, map));
  }
}

geometry_msgs::PoseWithCovarianceStamped ResultPublisher::poseMessage(const Job& job, const core::Candidate& best,
                                                                      const core::MapRayCaster& map) const
{
  const Batch& batch = job.batch;
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header.stamp = stampToTime(batch.newest_stamp);
  pose.header.frame_id = params_.global_frame_id;
  pose.pose.pose = toPoseMsg(carryForward(best.pose, batch.base_first, batch.base_newest));
  pose.pose.covariance = toCovariance6(
      carryForwardCovariance(usableCovariance(best, map), best.pose, batch.base_first, batch.base_newest));
  return pose;
}

void ResultPublisher::publishStatus(const fdml_localization::Status& status)
{
  status_pub_.publish(status);
}

void ResultPublisher::publishInitialPose(const Job& job, const core::Candidate& best, const core::MapRayCaster& map)
{
  initialpose_pub_.publish(poseMessage(job, best, map));
}

Eigen::Matrix3d ResultPublisher::usableCovariance(const core::Candidate& best, const core::MapRayCaster& map) const
{
  if (best.covariance.allFinite() && best.covariance.diagonal().minCoeff() > 0.0)
  {
    return best.covariance;
  }
  const core::Vec2 size = map.map().bounds().size();
  const int resolution = std::max(1, params_.localizer.resolution);
  const double cell = std::max(size.x(), size.y()) / resolution;
  const int theta_cells = params_.localizer.theta_resolution > 0 ? params_.localizer.theta_resolution : resolution;
  return Eigen::Vector3d(cell * cell, cell * cell, std::pow(core::kTwoPi / theta_cells, 2)).asDiagonal();
}

void ResultPublisher::publishMapToOdom(const core::Pose2& map_to_odom)
{
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = ros::Time::now() + ros::Duration(params_.transform_tolerance);
  transform.header.frame_id = params_.global_frame_id;
  transform.child_frame_id = params_.odom_frame_id;
  transform.transform = toTransformMsg(map_to_odom);
  tf_broadcaster_.sendTransform(transform);
}

void ResultPublisher::publishMapMarkers(const core::MapRayCaster& map)
{
  map_markers_pub_.publish(mapMarkers(map.map(), params_.global_frame_id, ros::Time::now()));
}

}  // namespace fdml_localization
