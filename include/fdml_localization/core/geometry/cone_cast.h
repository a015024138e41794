/**
 * @file cone_cast.h
 * @brief The reading model of a wide-cone range sensor: the nearest map point within a sector.
 *
 * A sensor at pose p with half-angle a reports the distance to the nearest point of any map
 * edge inside the sector {p.position + r (cos phi, sin phi) : r >= 0, phi in
 * [p.theta - a, p.theta + a]}, or nothing when no edge point of the sector lies within its
 * maximum range. With a = 0 this is the ray cast of MapRayCaster::range().
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/// Largest half-angle a cone reading may have [rad]: a half-plane.
constexpr double kMaxConeHalfAngle = 1.5707963267948966;

/**
 * @brief Distance from @p origin to the nearest point of @p seg inside the sector of unit
 *        directions @p right (heading - a) and @p left (heading + a), a in [0, pi/2].
 * @return the distance [m], +inf when the segment does not meet the sector
 */
double sectorSegmentDistance(const Vec2& origin, const Vec2& right, const Vec2& left, const Segment& seg);

/**
 * @brief The exact cone cast: distance from @p sensor to the nearest map edge point inside the
 *        sector of half-angle @p half_angle around its +x axis.
 * @param half_angle [rad] in [0, pi/2]; 0 casts the central ray
 * @param max_range [m]; points farther away are ignored
 * @return the distance [m], +inf when nothing lies in the sector within @p max_range
 */
double coneRange(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range = kInf);

/// The same answer by a loop over every segment (reference for tests).
double coneRangeBruteForce(const std::vector<Segment>& segments, const Pose2& sensor, double half_angle,
                           double max_range = kInf);

}  // namespace core
}  // namespace fdml_localization
