#include "fdml_localization/core/geometry/cone_cast.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
double cross(const Vec2& a, const Vec2& b)
{
  return a.x() * b.y() - a.y() * b.x();
}

/// Clips the parameter interval [lo, hi] of a + t (b - a) to the half-plane cross(n, p - o) >= 0.
bool clipHalfPlane(const Vec2& origin, const Vec2& n, const Segment& seg, double& lo, double& hi)
{
  const double fa = cross(n, seg.a - origin);
  const double fb = cross(n, seg.b - origin);
  if (fa < 0.0 && fb < 0.0)
  {
    return false;
  }
  if (fa >= 0.0 && fb >= 0.0)
  {
    return lo <= hi;
  }
  const double t = fa / (fa - fb);  // where the segment crosses the boundary line
  if (fa < 0.0)
  {
    lo = std::max(lo, t);
  }
  else
  {
    hi = std::min(hi, t);
  }
  return lo <= hi;
}
}  // namespace

double sectorSegmentDistance(const Vec2& origin, const Vec2& right, const Vec2& left, const Segment& seg)
{
  double lo = 0.0;
  double hi = 1.0;
  // The sector (opening at most pi) is the intersection of two half-planes through the origin.
  if (!clipHalfPlane(origin, right, seg, lo, hi) || !clipHalfPlane(origin, -left, seg, lo, hi))
  {
    return kInf;
  }
  const Vec2 d = seg.b - seg.a;
  const double len2 = d.squaredNorm();
  double t = lo;
  if (len2 > 0.0)
  {
    t = std::clamp((origin - seg.a).dot(d) / len2, lo, hi);
  }
  const Vec2 p = seg.a + t * d;
  // Both half-planes also hold the opposite sector when the opening is exactly pi: keep the
  // points in front of the sensor only.
  if ((p - origin).dot(right + left) < 0.0 && (p - origin).squaredNorm() > 0.0)
  {
    return kInf;
  }
  return (p - origin).norm();
}

double coneRangeBruteForce(const std::vector<Segment>& segments, const Pose2& sensor, double half_angle,
                           double max_range)
{
  const Vec2 origin(sensor.x, sensor.y);
  const Vec2 right(std::cos(sensor.theta - half_angle), std::sin(sensor.theta - half_angle));
  const Vec2 left(std::cos(sensor.theta + half_angle), std::sin(sensor.theta + half_angle));
  double best = kInf;
  for (const Segment& s : segments)
  {
    best = std::min(best, sectorSegmentDistance(origin, right, left, s));
  }
  return best <= max_range ? best : kInf;
}

double coneRange(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range)
{
  const double central = map.range(sensor, max_range);
  if (!(half_angle > 0.0))
  {
    return central;
  }
  // The central ray's hit lies in the sector, so nothing nearer than it can be farther away.
  const double radius = std::min(central, max_range);
  const Vec2 origin(sensor.x, sensor.y);
  const Vec2 right(std::cos(sensor.theta - half_angle), std::sin(sensor.theta - half_angle));
  const Vec2 left(std::cos(sensor.theta + half_angle), std::sin(sensor.theta + half_angle));
  const std::vector<Segment>& segments = map.grid().segments();
  double best = kInf;
  if (!std::isfinite(radius))
  {
    return coneRangeBruteForce(segments, sensor, half_angle, max_range);
  }
  Box2 box;
  box.min = origin - Vec2(radius, radius);
  box.max = origin + Vec2(radius, radius);
  map.grid().forEachSegmentInBox(box, [&](int i) {
    best = std::min(best, sectorSegmentDistance(origin, right, left, segments[static_cast<std::size_t>(i)]));
    return true;
  });
  return best <= max_range ? best : kInf;
}

}  // namespace core
}  // namespace fdml_localization
