/**
 * @file cone_cast.h
 * @brief The reading model of a wide-cone range sensor: the nearest point within a sector.
 *
 * A sensor at pose p with half-angle a reports the distance to the nearest point of any map
 * edge inside the closed sector {p.position + r (cos phi, sin phi) : r >= 0, phi in
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

/// A sector of directions: the apex and the unit directions of its two bounding rays.
struct Sector
{
  Vec2 origin = Vec2::Zero();  ///< apex [m]
  Vec2 right = Vec2::UnitX();  ///< unit direction at heading - a
  Vec2 left = Vec2::UnitX();   ///< unit direction at heading + a

  /// The sector of half-angle @p half_angle [rad] in [0, pi/2] around the pose's +x axis.
  static Sector around(const Pose2& sensor, double half_angle);
  /// True when @p p lies in the closed sector.
  bool contains(const Vec2& p) const;
};

/**
 * @brief Distance from the sector's apex to the nearest point of @p seg inside the sector
 *        (opening at most pi).
 * @return the distance [m], +inf when the segment does not meet the sector
 */
double sectorSegmentDistance(const Sector& sector, const Segment& seg);

/// The same, the sector given by its apex and bounding directions (see Sector).
double sectorSegmentDistance(const Vec2& origin, const Vec2& right, const Vec2& left, const Segment& seg);

/**
 * @brief Distance from the sector's apex to the nearest point of the solid disc (centre,
 *        radius) inside the sector: 0 when the apex is in the disc, +inf when the disc does
 *        not meet the sector. The nearest point of the disc when it lies in the sector, else
 *        the nearer entry point of the two bounding rays.
 * @param centre [m]
 * @param radius [m], >= 0
 */
double sectorCircleDistance(const Sector& sector, const Vec2& centre, double radius);

/**
 * @brief The exact cone cast: distance from @p sensor to the nearest map edge point inside the
 *        sector of half-angle @p half_angle around its +x axis.
 * @param half_angle [rad] in [0, pi/2]; 0 casts the central ray
 * @param max_range [m]; points farther away are ignored
 * @return the distance [m], +inf when nothing lies in the sector within @p max_range
 * @throws std::invalid_argument when @p half_angle is NaN or outside [0, pi/2]
 */
double coneRange(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range = kInf);

/// Where a cone cast found its nearest point.
struct ConeHit
{
  double distance = kInf;     ///< [m]; +inf when nothing lies in the sector within range
  Vec2 point = Vec2::Zero();  ///< the nearest point [m]
  int segment = -1;           ///< index of its edge in the map's grid segments, -1 on a miss
  /// 0: strictly inside the sector (an edge's perpendicular foot or an endpoint); -1 / +1: where
  /// the right / left bounding ray crosses the edge (a zero half-angle: the ray, +1).
  int side = 0;
};

/// coneRange() with where the nearest point lies (the same distance).
ConeHit coneCast(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range = kInf);

/**
 * @brief coneCast() bounded by @p hint, a point of a map edge (typically the previous hit of a
 *        nearby pose, as in the polish): when it lies in the sector its distance bounds the
 *        search instead of the central ray's cast, which saves that cast and shrinks the cells
 *        visited. The same answer for any hint (a hint that is no map point, or NaN, falls back to
 *        coneCast()).
 */
ConeHit coneCast(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range, const Vec2& hint);

/**
 * @brief The derivative of the cone range at @p hit (from coneCast(map, sensor, half_angle))
 *        with respect to the sensor's x, y [m] and heading [rad]. A nearest point strictly
 *        inside the sector: minus the unit vector to it for the position, 0 for the heading
 *        (turning the sector does not move it: the reading does not fix the heading). On a
 *        bounding ray: that ray's derivative, -n / (n.u) and -d (n.u_perp) / (n.u), n the edge's
 *        normal, u the ray's direction.
 * @return (dd/dx, dd/dy, dd/dtheta); zeros on a miss, at distance 0 or along an edge parallel
 *         to the bounding ray
 */
Eigen::RowVector3d coneRangeDerivative(const MapRayCaster& map, const Pose2& sensor, double half_angle,
                                       const ConeHit& hit);

/// The same answer by a loop over every segment (reference for tests).
double coneRangeBruteForce(const std::vector<Segment>& segments, const Pose2& sensor, double half_angle,
                           double max_range = kInf);

}  // namespace core
}  // namespace fdml_localization
