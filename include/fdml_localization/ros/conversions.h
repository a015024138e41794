/**
 * @file conversions.h
 * @brief Conversions between ROS messages and the ROS-free core types.
 */
#pragma once

#include "fdml_localization/core/localizer.h"
#include "fdml_localization/core/polygon_map.h"
#include "fdml_localization/ros/reading_buffer.h"

#include <fdml_localization/Candidate.h>
#include <fdml_localization/LocalizationResult.h>
#include <fdml_localization/Reading.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Pose2D.h>
#include <geometry_msgs/PoseWithCovariance.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <visualization_msgs/Marker.h>
#include <visualization_msgs/MarkerArray.h>

#include <Eigen/Core>

#include <map>
#include <string>
#include <vector>

namespace fdml_localization
{
// ---------------------------------------------------------------------------------------------
// Localizer node conversions: poses, readings, results, sensor input, markers.
// ---------------------------------------------------------------------------------------------

/// Quaternion of a rotation by @p yaw [rad] about +z.
geometry_msgs::Quaternion yawToQuaternion(double yaw);
/// Yaw [rad] in [-pi, pi) of a quaternion (its rotation projected on the plane, normalised or not);
/// a zero or non-finite quaternion gives 0.
double quaternionToYaw(const geometry_msgs::Quaternion& q);

geometry_msgs::Pose toPoseMsg(const core::Pose2& pose);
core::Pose2 fromPoseMsg(const geometry_msgs::Pose& pose);
geometry_msgs::Pose2D toPose2D(const core::Pose2& pose);
core::Pose2 fromPose2D(const geometry_msgs::Pose2D& pose);
geometry_msgs::Transform toTransformMsg(const core::Pose2& pose);
core::Pose2 fromTransformMsg(const geometry_msgs::Transform& transform);

/// The 6x6 row-major (x, y, z, roll, pitch, yaw) covariance of a planar 3x3 (x, y, theta) one;
/// z, roll and pitch get zero variance.
boost::array<double, 36> toCovariance6(const Eigen::Matrix3d& covariance);
/// The (x, y, theta) block of a 6x6 row-major covariance.
Eigen::Matrix3d fromCovariance6(const boost::array<double, 36>& covariance);

fdml_localization::Reading toReadingMsg(const core::Reading& reading);
core::Reading fromReadingMsg(const fdml_localization::Reading& reading);
std::vector<core::Reading> fromReadingMsgs(const std::vector<fdml_localization::Reading>& readings);

fdml_localization::Candidate toCandidateMsg(const core::Candidate& candidate);

/// The result message (candidates, counts, engine, method, stage times); the caller fills the
/// header and the drop counts (see setDropCounts()).
fdml_localization::LocalizationResult toResultMsg(const core::Result& result);
/// Copies drop counters into the result's drop_reasons / drop_counts (sorted by reason).
void setDropCounts(const std::map<std::string, std::uint64_t>& drops, fdml_localization::LocalizationResult* msg);

/**
 * @brief A sensor_msgs/Range as a reading, with REP-117 semantics: +inf is a no-return reading;
 *        NaN, -inf ("too close") and values outside [min_range, max_range] are dropped.
 * @param received arrival time on the node's clock [s]
 * @param[out] reading set when the reading is usable
 * @param[out] reason the drop reason (a drop_reason:: identifier) when it is not
 * @return true when usable
 */
bool rangeToReading(const sensor_msgs::Range& msg, double received, TimedReading* reading, std::string* reason);

/**
 * @brief Up to @p beams evenly spaced usable beams of a scan (REP-117 per beam, as for a
 *        Range: +inf is a no-return, NaN, -inf and values outside [range_min, range_max] are
 *        unusable). Beam i is stamped
 *        header.stamp + i * time_increment and posed (0, 0, angle_min + i * angle_increment)
 *        in the scan frame.
 * @param[out] drops counts of unusable beams by reason
 */
std::vector<TimedReading> scanToReadings(const sensor_msgs::LaserScan& msg, int beams, double received,
                                         std::map<std::string, std::uint64_t>* drops);

/// The map's rings as one LINE_LIST marker (namespace "map", id 0) in @p frame_id.
visualization_msgs::Marker mapMarker(const core::PolygonMap& map, const std::string& frame_id);

/**
 * @brief The rays of a batch seen from a candidate pose: one LINE_LIST (namespace "rays", id 0)
 *        from each sensor pose q (+) g_i to its hit point, green for an inlier, red for an
 *        outlier, grey for a no-return ray (drawn to max_range, at most @p no_return_length m),
 *        and a SPHERE_LIST of the hit points (namespace "hits", id 1). Starts with a DELETEALL.
 * @param inlier_mask per reading (may be empty: every ray is then drawn as an inlier)
 */
visualization_msgs::MarkerArray readingMarkers(const std::vector<core::Reading>& readings, const core::Pose2& pose,
                                               const std::vector<bool>& inlier_mask, const std::string& frame_id,
                                               const ros::Time& stamp, double no_return_length = 1.0);

}  // namespace fdml_localization
