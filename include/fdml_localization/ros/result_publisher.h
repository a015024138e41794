/**
 * @file result_publisher.h
 * @brief The localizer node's outputs: ~result, ~candidates, ~pose, ~status, the reading and
 *        map markers, map -> odom on tf, and (~publish_initialpose) the hand-over on initialpose.
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/ros/node_state.h"
#include "fdml_localization/ros/params.h"

#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include <Eigen/Core>

namespace fdml_localization
{
/// Pose of the base at the newest reading: @p pose (the base at t_1 in the map) carried forward
/// by the odometry between @p base_first and @p base_newest (both in odom).
core::Pose2 carryForward(const core::Pose2& pose, const core::Pose2& base_first, const core::Pose2& base_newest);

/// The covariance of carryForward()'s result from the covariance of @p pose (first order).
Eigen::Matrix3d carryForwardCovariance(const Eigen::Matrix3d& covariance, const core::Pose2& pose,
                                       const core::Pose2& base_first, const core::Pose2& base_newest);

/// Publishes what the worker found. Called from the worker and the tf timer; holds no state
/// that needs the node's mutex.
class ResultPublisher
{
public:
  /// @param nh the node's namespace (initialpose); @p private_nh the outputs' namespace
  ResultPublisher(ros::NodeHandle& nh, ros::NodeHandle& private_nh, const Params& params);

  /**
   * @brief Publishes a solved sensor batch: ~result, ~candidates and the reading markers always;
   *        ~pose (and map -> odom) only when @p unambiguous.
   * @param map the map the batch was solved on (for the fallback covariance)
   */
  void publishBatch(const Job& job, const core::Result& result, const Outcome& outcome, bool unambiguous,
                    const core::MapRayCaster& map);

  /// Broadcasts map -> odom, future-dated by ~transform_tolerance like AMCL.
  void publishMapToOdom(const core::Pose2& map_to_odom);

  /// Publishes ~status.
  void publishStatus(const fdml_localization::Status& status);

  /// Hands a clearly supported fix over to a downstream AMCL: @p best (the base at the batch's
  /// first reading) carried forward to the newest reading, on initialpose.
  void publishInitialPose(const Job& job, const core::Candidate& best, const core::MapRayCaster& map);

  /// Publishes the map's walls (latched).
  void publishMapMarkers(const core::MapRayCaster& map);

private:
  /// The ~pose message of @p best (carried forward to the batch's newest reading).
  geometry_msgs::PoseWithCovarianceStamped poseMessage(const Job& job, const core::Candidate& best,
                                                       const core::MapRayCaster& map) const;
  /// The best candidate's covariance, or one grid cell in each direction when the polish gave
  /// none.
  Eigen::Matrix3d usableCovariance(const core::Candidate& best, const core::MapRayCaster& map) const;

  const Params& params_;
  ros::Publisher candidates_pub_;
  ros::Publisher result_pub_;
  ros::Publisher pose_pub_;
  ros::Publisher status_pub_;
  ros::Publisher initialpose_pub_;  ///< with ~publish_initialpose only
  ros::Publisher map_markers_pub_;
  ros::Publisher reading_markers_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
};

}  // namespace fdml_localization
