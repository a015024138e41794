/**
 * @file conversions.h
 * @brief Free functions converting between the ROS-free core types and ROS messages:
 *        poses, yaw and quaternions, transforms, covariances, occupancy grids, readings and
 *        results. Markers are in markers.h, sensor checks in sensor_input.h.
 *        Planar poses live in the z = 0 plane; units [m], [rad].
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/map/grid/occupancy_grid.h"

#include <fdml_localization/Candidate.h>
#include <fdml_localization/LocalizationResult.h>
#include <fdml_localization/Reading.h>

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Pose2D.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/time.h>

#include <Eigen/Core>

#include <boost/array.hpp>

#include <cstdint>
#include <map>

#include <string>
#include <vector>

namespace fdml_localization
{
/// A reading stamp [ns since the epoch] as a ros::Time (negative stamps clamp to 0).
ros::Time stampToTime(std::int64_t stamp);

/// Pose2 -> geometry_msgs/Pose2D.
geometry_msgs::Pose2D toPose2D(const core::Pose2& pose);
/// geometry_msgs/Pose2D -> Pose2 (theta wrapped to [-pi, pi)).
core::Pose2 fromPose2D(const geometry_msgs::Pose2D& pose);

/// A rotation about +z by @p yaw [rad].
geometry_msgs::Quaternion yawToQuaternion(double yaw);
/// The yaw [rad] in [-pi, pi) of a quaternion (rotation about +z after projecting to the plane,
/// normalised or not); a zero or non-finite quaternion gives 0.
double quaternionToYaw(const geometry_msgs::Quaternion& q);

/// Pose2 -> geometry_msgs/Pose at z = 0.
geometry_msgs::Pose toPoseMsg(const core::Pose2& pose);
/// geometry_msgs/Pose -> Pose2 (drops z, roll and pitch).
core::Pose2 fromPoseMsg(const geometry_msgs::Pose& pose);

/// Pose2 -> geometry_msgs/Transform at z = 0.
geometry_msgs::Transform toTransformMsg(const core::Pose2& pose);
/// geometry_msgs/Transform -> Pose2 (drops z, roll and pitch).
core::Pose2 fromTransformMsg(const geometry_msgs::Transform& transform);

/// A point at height @p z [m].
geometry_msgs::Point toPointMsg(const core::Vec2& p, double z = 0.0);

/**
 * @brief A nav_msgs/OccupancyGrid as a core grid: sizes, resolution and cells copied unchanged
 *        (both are row-major with row 0 at the bottom), the origin's position and its yaw (from
 *        the quaternion, see quaternionToYaw()). A message whose data size does not match
 *        width * height is copied as is: core::OccupancyGrid::validate() reports it.
 */
core::OccupancyGrid fromOccupancyGridMsg(const nav_msgs::OccupancyGrid& msg);

/// A core grid as a nav_msgs/OccupancyGrid (origin at z = 0, yaw as a quaternion about +z).
nav_msgs::OccupancyGrid toOccupancyGridMsg(const core::OccupancyGrid& grid, const std::string& frame,
                                           const ros::Time& stamp);

// ---------------------------------------------------------------------------------------------
// Localizer node conversions (issue 6): covariance, readings, results, sensor input, rays.
// ---------------------------------------------------------------------------------------------

/// The 6x6 row-major (x, y, z, roll, pitch, yaw) covariance of a planar 3x3 (x, y, theta) one;
/// z, roll and pitch get zero variance.
boost::array<double, 36> toCovariance6(const Eigen::Matrix3d& covariance);
/// The (x, y, theta) block of a 6x6 row-major covariance.
Eigen::Matrix3d fromCovariance6(const boost::array<double, 36>& covariance);

/**
 * @brief The cone half-angle of a sensor's full field of view: fov / 2 [rad].
 * @param field_of_view [rad]; valid when finite and in [0, pi] (a float32 pi, slightly above
 *        pi, counts as pi)
 * @param[out] half_angle in [0, pi/2] when valid
 * @return false when @p field_of_view is invalid (@p half_angle untouched)
 */
bool fieldOfViewToHalfAngle(double field_of_view, double* half_angle);

/// The message of a reading; field_of_view = 2 half_angle.
fdml_localization::Reading toReadingMsg(const core::Reading& reading);
/// The reading of a message; half_angle = field_of_view / 2.
/// @throws std::invalid_argument "field_of_view: ..." when field_of_view is invalid
core::Reading fromReadingMsg(const fdml_localization::Reading& reading);
/// @throws std::invalid_argument "readings[i].field_of_view: ..." naming the first invalid one
std::vector<core::Reading> fromReadingMsgs(const std::vector<fdml_localization::Reading>& readings);

fdml_localization::Candidate toCandidateMsg(const core::Candidate& candidate);

/// The result message (candidates, counts, engine, method, stage times); the caller fills the
/// header and the drop counts (see setDropCounts()).
fdml_localization::LocalizationResult toResultMsg(const core::Result& result);
/// Copies drop counters into the result's drop_reasons / drop_counts (sorted by reason).
void setDropCounts(const std::map<std::string, std::uint64_t>& drops, fdml_localization::LocalizationResult* msg);

}  // namespace fdml_localization
