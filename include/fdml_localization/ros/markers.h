/**
 * @file markers.h
 * @brief rviz markers: the map's walls, the simulator's obstacles, a batch's rays seen from a
 *        candidate pose. Units [m].
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/map/polygon_map.h"
#include "fdml_localization/simulation/scene.h"

#include <ros/time.h>
#include <std_msgs/ColorRGBA.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>
#include <vector>

namespace fdml_localization
{
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
visualization_msgs::MarkerArray obstacleMarkers(const std::vector<core::Obstacle>& obstacles, const std::string& frame,
                                                const ros::Time& stamp, std::size_t previous_count = 0);

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
