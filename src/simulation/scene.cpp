#include "fdml_localization/simulation/scene.h"

#include <algorithm>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Makes @p hit the nearest obstacle within @p max_range when one is nearer than its map hit.
template <typename Distance>
void nearestObstacle(const std::vector<Obstacle>& obstacles, double max_range, Distance&& distance, SceneHit* hit)
{
  for (std::size_t i = 0; i < obstacles.size(); ++i)
  {
    const double t = distance(obstacles[i]);
    if (t <= max_range && t < hit->distance)
    {
      hit->kind = SceneHit::Kind::Obstacle;
      hit->distance = t;
      hit->obstacle = static_cast<int>(i);
    }
  }
}
}  // namespace

Obstacle Obstacle::disc(const Vec2& centre, double radius)
{
  Obstacle o;
  o.shape = Shape::Disc;
  o.centre = centre;
  o.radius = radius;
  return o;
}

Obstacle Obstacle::polygon(const Ring& vertices)
{
  Obstacle o;
  o.shape = Shape::Polygon;
  o.vertices = cleanRing(vertices);
  if (o.vertices.size() < 3)
  {
    throw std::invalid_argument("polygon obstacle needs at least 3 distinct vertices");
  }
  Vec2 sum = Vec2::Zero();
  for (const Vec2& v : o.vertices)
  {
    sum += v;
  }
  o.centre = sum / static_cast<double>(o.vertices.size());
  return o;
}

bool Obstacle::contains(const Vec2& p) const
{
  if (shape == Shape::Disc)
  {
    return (p - centre).squaredNorm() <= radius * radius;
  }
  return pointInRing(p, vertices);
}

Box2 Obstacle::bounds() const
{
  Box2 box;
  if (shape == Shape::Disc)
  {
    box.extend(centre - Vec2(radius, radius));
    box.extend(centre + Vec2(radius, radius));
    return box;
  }
  for (const Vec2& v : vertices)
  {
    box.extend(v);
  }
  return box;
}

double Obstacle::castDistance(const Vec2& origin, const Vec2& dir) const
{
  if (shape == Shape::Disc)
  {
    return rayCircleDistance(origin, dir, centre, radius);
  }
  if (pointInRing(origin, vertices))
  {
    return 0.0;  // a sensor inside an obstacle sees it at once, as with a disc
  }
  // The same segment primitive as the static map's grid cast.
  double best = kInf;
  const std::size_t n = vertices.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    best = std::min(best, raySegmentDistance(origin, dir, Segment{ vertices[i], vertices[(i + 1) % n] }));
  }
  return best;
}

double Obstacle::sectorDistance(const Sector& sector) const
{
  if (shape == Shape::Disc)
  {
    return sectorCircleDistance(sector, centre, radius);
  }
  if (pointInRing(sector.origin, vertices))
  {
    return 0.0;
  }
  double best = kInf;
  const std::size_t n = vertices.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    best = std::min(best, sectorSegmentDistance(sector, Segment{ vertices[i], vertices[(i + 1) % n] }));
  }
  return best;
}

Scene::Scene(std::shared_ptr<const MapRayCaster> map) : map_(std::move(map))
{
  if (!map_)
  {
    throw std::invalid_argument("Scene needs a map");
  }
}

SceneHit Scene::cast(const Pose2& sensor, double max_range) const
{
  const Vec2 origin = sensor.position();
  const Vec2 dir = sensor.heading();
  SceneHit hit;
  hit.map_distance = map_->cast(origin, dir, max_range).distance;
  if (hit.map_distance <= max_range)
  {
    hit.kind = SceneHit::Kind::Map;
    hit.distance = hit.map_distance;
  }
  nearestObstacle(
      obstacles_, max_range, [&](const Obstacle& o) { return o.castDistance(origin, dir); }, &hit);
  return hit;
}

SceneHit Scene::castCone(const Pose2& sensor, double half_angle, double max_range) const
{
  if (half_angle == 0.0)
  {
    return cast(sensor, max_range);
  }
  SceneHit hit;
  hit.map_distance = coneRange(*map_, sensor, half_angle, max_range);
  if (hit.map_distance <= max_range)
  {
    hit.kind = SceneHit::Kind::Map;
    hit.distance = hit.map_distance;
  }
  const Sector sector = Sector::around(sensor, half_angle);
  nearestObstacle(
      obstacles_, max_range, [&](const Obstacle& o) { return o.sectorDistance(sector); }, &hit);
  return hit;
}

bool Scene::isFree(const Vec2& p) const
{
  return map_->isFree(p) &&
         std::none_of(obstacles_.begin(), obstacles_.end(), [&p](const Obstacle& o) { return o.contains(p); });
}

}  // namespace core
}  // namespace fdml_localization
