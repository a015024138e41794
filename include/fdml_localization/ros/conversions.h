/**
 * @file conversions.h
 * @brief Free functions converting between the ROS-free core types and ROS messages:
 *        poses, yaw and quaternions, transforms, and visualization of maps and obstacles.
 *        Planar poses live in the z = 0 plane; units [m], [rad].
 */
#pragma once

#include "fdml_localization/core/ray_caster.h"
#include "fdml_localization/core/scene.h"

#include <geometry_msgs/Point.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Pose2D.h>
#include <geometry_msgs/Quaternion.h>
#include <geometry_msgs/Transform.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/time.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>
#include <vector>

namespace fdml_localization
{
/// Pose2 -> geometry_msgs/Pose2D.
geometry_msgs::Pose2D toPose2D(const core::Pose2& pose);
/// geometry_msgs/Pose2D -> Pose2 (theta wrapped to [-pi, pi)).
core::Pose2 fromPose2D(const geometry_msgs::Pose2D& pose);

/// A rotation about +z by @p yaw [rad].
geometry_msgs::Quaternion yawToQuaternion(double yaw);
/// The yaw [rad] of a quaternion (rotation about +z after projecting to the plane); a
/// zero or non-finite quaternion gives 0.
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

/// A colour from components in [0, 1].
std_msgs::ColorRGBA makeColor(float r, float g, float b, float a = 1.0f);

/**
 * @brief The map's walls as markers: one LINE_LIST of every edge (namespace "map_walls").
 * @param map the polygon map
 * @param frame frame of the map
 * @param stamp header stamp
 */
visualization_msgs::MarkerArray mapMarkers(const core::PolygonMap& map, const std::string& frame,
                                           const ros::Time& stamp);

/**
 * @brief Obstacles as markers, id = obstacle index, namespace "obstacles": a CYLINDER for a
 *        disc, a closed LINE_STRIP for a polygon. Markers of ids >= obstacles.size() up to
 *        @p previous_count are deleted.
 */
visualization_msgs::MarkerArray obstacleMarkers(const std::vector<core::Obstacle>& obstacles,
                                                const std::string& frame, const ros::Time& stamp,
                                                std::size_t previous_count = 0);

/**
 * @brief Rasterizes the map: a cell is occupied (100) when a wall passes through it or its
 *        centre is inside a hole, free (0) when its centre is in free space, unknown (-1)
 *        outside the outer boundary.
 * @param caster the map prepared for queries
 * @param resolution cell size [m] (> 0)
 * @param frame frame of the map
 * @param stamp header stamp
 */
nav_msgs::OccupancyGrid toOccupancyGrid(const core::MapRayCaster& caster, double resolution,
                                        const std::string& frame, const ros::Time& stamp);

}  // namespace fdml_localization
