#include "fdml_localization/core/geometry/cone_cast.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Slack on the pruning tests [m]: a cell on the exact bound is visited.
constexpr double kPruneSlack = 1e-9;

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

/// The bounding box of the sector cut at @p radius: the apex, the ends of the bounding rays and
/// the arc's extreme points along the axes that the sector contains.
Box2 sectorBox(const Sector& sector, double radius)
{
  Box2 box;
  box.extend(sector.origin);
  box.extend(sector.origin + radius * sector.right);
  box.extend(sector.origin + radius * sector.left);
  for (const Vec2& axis : { Vec2(1.0, 0.0), Vec2(-1.0, 0.0), Vec2(0.0, 1.0), Vec2(0.0, -1.0) })
  {
    if (sector.contains(sector.origin + axis))
    {
      box.extend(sector.origin + radius * axis);
    }
  }
  return box;
}

/// False only when the box lies strictly outside one of the sector's two half-planes.
bool mayMeetSector(const Sector& sector, const Box2& box)
{
  const Vec2 corners[4] = { box.min, Vec2(box.max.x(), box.min.y()), box.max, Vec2(box.min.x(), box.max.y()) };
  bool right_side = false;
  bool left_side = false;
  for (const Vec2& c : corners)
  {
    right_side = right_side || cross(sector.right, c - sector.origin) >= -kPruneSlack;
    left_side = left_side || cross(sector.left, c - sector.origin) <= kPruneSlack;
  }
  return right_side && left_side;
}

double boxDistanceSquared(const Vec2& p, const Box2& box)
{
  const double dx = std::max({ box.min.x() - p.x(), 0.0, p.x() - box.max.x() });
  const double dy = std::max({ box.min.y() - p.y(), 0.0, p.y() - box.max.y() });
  return dx * dx + dy * dy;
}
}  // namespace

Sector Sector::around(const Pose2& sensor, double half_angle)
{
  Sector s;
  s.origin = sensor.position();
  s.right = Vec2(std::cos(sensor.theta - half_angle), std::sin(sensor.theta - half_angle));
  s.left = Vec2(std::cos(sensor.theta + half_angle), std::sin(sensor.theta + half_angle));
  return s;
}

bool Sector::contains(const Vec2& p) const
{
  // The sector (opening at most pi) is the intersection of two half-planes through the apex.
  return cross(right, p - origin) >= 0.0 && cross(left, p - origin) <= 0.0;
}

double sectorSegmentDistance(const Sector& sector, const Segment& seg)
{
  double lo = 0.0;
  double hi = 1.0;
  if (!clipHalfPlane(sector.origin, sector.right, seg, lo, hi) ||
      !clipHalfPlane(sector.origin, -sector.left, seg, lo, hi))
  {
    return kInf;
  }
  // The nearest point of the clipped part: the perpendicular foot clamped to it.
  const Vec2 d = seg.b - seg.a;
  const double len2 = d.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((sector.origin - seg.a).dot(d) / len2, lo, hi) : lo;
  return (seg.a + t * d - sector.origin).norm();
}

double sectorSegmentDistance(const Vec2& origin, const Vec2& right, const Vec2& left, const Segment& seg)
{
  return sectorSegmentDistance(Sector{ origin, right, left }, seg);
}

double sectorCircleDistance(const Sector& sector, const Vec2& centre, double radius)
{
  const double d = (centre - sector.origin).norm();
  if (d <= radius)
  {
    return 0.0;
  }
  // The disc's nearest point lies on the line to the centre: in the sector with the centre.
  if (sector.contains(centre))
  {
    return d - radius;
  }
  // Otherwise the minimum over the convex set disc n sector lies on the sector's boundary.
  return std::min(rayCircleDistance(sector.origin, sector.right, centre, radius),
                  rayCircleDistance(sector.origin, sector.left, centre, radius));
}

double coneRangeBruteForce(const std::vector<Segment>& segments, const Pose2& sensor, double half_angle,
                           double max_range)
{
  const Sector sector = Sector::around(sensor, half_angle);
  double best = kInf;
  for (const Segment& s : segments)
  {
    best = std::min(best, sectorSegmentDistance(sector, s));
  }
  return best <= max_range ? best : kInf;
}

double coneRange(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range)
{
  if (!(half_angle >= 0.0 && half_angle <= kMaxConeHalfAngle))
  {
    throw std::invalid_argument("coneRange: half_angle " + std::to_string(half_angle) + " rad must be in [0, pi/2]");
  }
  if (half_angle == 0.0)
  {
    return map.range(sensor, max_range);
  }
  const Sector sector = Sector::around(sensor, half_angle);
  const SegmentGrid& grid = map.grid();
  // The central ray's hit lies in the sector, so the answer is no farther: it bounds the search
  // (the bounding rays' hits would too, but casting them costs more than they save).
  const double bound = std::min(max_range, map.range(sensor, max_range));
  const std::vector<Segment>& segments = grid.segments();
  if (!std::isfinite(bound))
  {
    return coneRangeBruteForce(segments, sensor, half_angle, max_range);
  }
  double best = kInf;
  grid.forEachCellInBox(sectorBox(sector, bound), [&](const Box2& cell, const int* first, const int* last) {
    const double limit = std::min(best, bound) + kPruneSlack;
    if (boxDistanceSquared(sector.origin, cell) > limit * limit || !mayMeetSector(sector, cell))
    {
      return true;
    }
    for (const int* i = first; i != last; ++i)
    {
      best = std::min(best, sectorSegmentDistance(sector, segments[static_cast<std::size_t>(*i)]));
    }
    return true;
  });
  return best <= max_range ? best : kInf;
}

}  // namespace core
}  // namespace fdml_localization
