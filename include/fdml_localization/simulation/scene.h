/**
 * @file scene.h
 * @brief The static map plus dynamic obstacles (discs and polygons), for simulation:
 *        one cast returns the nearest of the map's hit and every obstacle's hit.
 */
#pragma once

#include "fdml_localization/core/geometry/cone_cast.h"

#include <memory>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A dynamic obstacle: a disc (radius > 0) or a polygon (vertices in the map frame).
struct Obstacle
{
  enum class Shape
  {
    Disc,
    Polygon
  };
  Shape shape = Shape::Disc;
  Vec2 centre = Vec2::Zero();  ///< disc centre [m] (for a polygon: a reference point)
  double radius = 0.1;         ///< disc radius [m]
  Ring vertices;               ///< polygon vertices [m], map frame

  static Obstacle disc(const Vec2& centre, double radius);
  static Obstacle polygon(const Ring& vertices);

  /// True when the point lies inside the obstacle.
  bool contains(const Vec2& p) const;
  /// Axis-aligned bounds [m].
  Box2 bounds() const;
  /// Nearest hit of a ray on the obstacle's boundary [m] (+inf on a miss; 0 when the origin is inside).
  double castDistance(const Vec2& origin, const Vec2& dir) const;
  /// Distance from the sector's apex to the obstacle's nearest point inside the sector [m]
  /// (+inf when it does not meet the sector; 0 when the apex is inside).
  double sectorDistance(const Sector& sector) const;
};

/// What a scene ray cast hit first.
struct SceneHit
{
  enum class Kind
  {
    None,
    Map,
    Obstacle
  };
  Kind kind = Kind::None;
  double distance = kInf;      ///< [m]
  int obstacle = -1;           ///< obstacle index when kind == Obstacle
  double map_distance = kInf;  ///< distance to the static map alone [m]
};

/// A static map shared between scenes, plus this scene's obstacles.
class Scene
{
public:
  explicit Scene(std::shared_ptr<const MapRayCaster> map);

  void setObstacles(std::vector<Obstacle> obstacles)
  {
    obstacles_ = std::move(obstacles);
  }
  const std::vector<Obstacle>& obstacles() const
  {
    return obstacles_;
  }
  const MapRayCaster& map() const
  {
    return *map_;
  }

  /// Nearest hit from @p sensor along its +x axis within @p max_range.
  SceneHit cast(const Pose2& sensor, double max_range = kInf) const;

  /**
   * @brief Nearest point of the map or an obstacle inside the sector of half-angle
   *        @p half_angle [rad] in [0, pi/2] around the sensor's +x axis, within @p max_range
   *        (the cone sensor's reading, cone_cast.h). half_angle = 0 is cast().
   */
  SceneHit castCone(const Pose2& sensor, double half_angle, double max_range = kInf) const;

  /// True when p is free in the map and outside every obstacle.
  bool isFree(const Vec2& p) const;

private:
  std::shared_ptr<const MapRayCaster> map_;
  std::vector<Obstacle> obstacles_;
};

}  // namespace core
}  // namespace fdml_localization
