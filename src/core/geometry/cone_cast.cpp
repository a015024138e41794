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

/// The nearest point of one segment inside a sector (see sectorSegmentNearest).
struct SectorPoint
{
  double distance = kInf;  ///< [m]
  double t = 0.0;          ///< parameter of the point on the segment, a + t (b - a)
  int side = 0;            ///< ConeHit::side
  double lo = 0.0;         ///< the segment's part inside the sector: [lo, hi]
  double hi = 1.0;
  int lo_side = 0;  ///< the bounding ray that cut the part at lo (-1 right, +1 left), 0 = the endpoint
  int hi_side = 0;
};

/// Clips the parameter interval [lo, hi] of a + t (b - a) to the half-plane cross(n, p - o) >= 0;
/// @p side is recorded in lo_side or hi_side when the boundary line moves that end.
bool clipHalfPlane(const Vec2& origin, const Vec2& n, const Segment& seg, int side, SectorPoint& out)
{
  const double fa = cross(n, seg.a - origin);
  const double fb = cross(n, seg.b - origin);
  if (fa < 0.0 && fb < 0.0)
  {
    return false;
  }
  if (fa >= 0.0 && fb >= 0.0)
  {
    return out.lo <= out.hi;
  }
  const double t = fa / (fa - fb);  // where the segment crosses the boundary line
  if (fa < 0.0 && t > out.lo)
  {
    out.lo = t;
    out.lo_side = side;
  }
  else if (fa >= 0.0 && t < out.hi)
  {
    out.hi = t;
    out.hi_side = side;
  }
  return out.lo <= out.hi;
}

/// The nearest point of @p seg inside the sector: its distance, where it lies on the segment
/// and on which bounding ray (ConeHit::side).
SectorPoint sectorSegmentNearest(const Sector& sector, const Segment& seg)
{
  SectorPoint out;
  if (!clipHalfPlane(sector.origin, sector.right, seg, -1, out) ||
      !clipHalfPlane(sector.origin, -sector.left, seg, 1, out))
  {
    return out;
  }
  // The nearest point of the clipped part: the perpendicular foot clamped to it.
  const Vec2 d = seg.b - seg.a;
  const double len2 = d.squaredNorm();
  const double foot = len2 > 0.0 ? (sector.origin - seg.a).dot(d) / len2 : out.lo;
  out.t = std::clamp(foot, out.lo, out.hi);
  out.side = foot < out.lo ? out.lo_side : (foot > out.hi ? out.hi_side : 0);
  out.distance = (seg.a + out.t * d - sector.origin).norm();
  return out;
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
  return sectorSegmentNearest(sector, seg).distance;
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

namespace
{
/// The nearest point found so far: its segment and where it lies on it.
struct Nearest
{
  SectorPoint point;
  int segment = -1;
};

/// Makes @p best segment @p index's nearest point in the sector when that one is nearer.
void keepNearer(const Sector& sector, const std::vector<Segment>& segments, int index, Nearest& best)
{
  const SectorPoint p = sectorSegmentNearest(sector, segments[static_cast<std::size_t>(index)]);
  if (p.distance < best.point.distance)
  {
    best.point = p;
    best.segment = index;
  }
}

/// The cone hit of @p best, or a miss beyond @p max_range.
ConeHit toHit(const std::vector<Segment>& segments, const Nearest& best, double max_range)
{
  ConeHit out;
  if (best.segment >= 0 && best.point.distance <= max_range)
  {
    const Segment& seg = segments[static_cast<std::size_t>(best.segment)];
    out.distance = best.point.distance;
    out.segment = best.segment;
    out.side = best.point.side;
    out.point = seg.a + best.point.t * (seg.b - seg.a);
  }
  return out;
}

/// The central ray as a cone hit (on the ray: side +1).
ConeHit rayHit(const MapRayCaster& map, const Pose2& sensor, double max_range)
{
  ConeHit out;
  const Vec2 dir = sensor.heading();
  const RayHit ray = map.cast(sensor.position(), dir, max_range);
  if (ray.hit() && std::isfinite(ray.distance))
  {
    out.distance = ray.distance;
    out.segment = ray.segment;
    out.side = 1;
    out.point = sensor.position() + ray.distance * dir;
  }
  return out;
}
}  // namespace

namespace
{
void checkHalfAngle(double half_angle)
{
  if (!(half_angle >= 0.0 && half_angle <= kMaxConeHalfAngle))
  {
    throw std::invalid_argument("coneRange: half_angle " + std::to_string(half_angle) + " rad must be in [0, pi/2]");
  }
}

/// The nearest point of the sector among the edges of the grid cells that meet it within
/// @p bound [m] (finite): exact when some edge point of the sector lies within the bound.
Nearest searchSector(const SegmentGrid& grid, const Sector& sector, double bound)
{
  const std::vector<Segment>& segments = grid.segments();
  Nearest best;
  grid.forEachCellInBox(sectorBox(sector, bound), [&](const Box2& cell, const int* first, const int* last) {
    const double limit = std::min(best.point.distance, bound) + kPruneSlack;
    if (first == last || boxDistanceSquared(sector.origin, cell) > limit * limit || !mayMeetSector(sector, cell))
    {
      return true;
    }
    for (const int* i = first; i != last; ++i)
    {
      keepNearer(sector, segments, *i, best);
    }
    return true;
  });
  return best;
}
}  // namespace

double coneRange(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range)
{
  return coneCast(map, sensor, half_angle, max_range).distance;
}

ConeHit coneCast(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range)
{
  checkHalfAngle(half_angle);
  const ConeHit central = rayHit(map, sensor, max_range);
  if (half_angle == 0.0)
  {
    return central;
  }
  const Sector sector = Sector::around(sensor, half_angle);
  const std::vector<Segment>& segments = map.grid().segments();
  // The central ray's hit lies in the sector, so the answer is no farther: it bounds the search
  // (the bounding rays' hits would too, but casting them costs more than they save).
  const double bound = std::min(max_range, central.distance);
  if (std::isfinite(bound))
  {
    return toHit(segments, searchSector(map.grid(), sector, bound), max_range);
  }
  Nearest best;
  for (int i = 0; i < static_cast<int>(segments.size()); ++i)
  {
    keepNearer(sector, segments, i, best);
  }
  return toHit(segments, best, max_range);
}

ConeHit coneCast(const MapRayCaster& map, const Pose2& sensor, double half_angle, double max_range, const Vec2& hint)
{
  checkHalfAngle(half_angle);
  if (half_angle > 0.0 && hint.allFinite())
  {
    const Sector sector = Sector::around(sensor, half_angle);
    if (sector.contains(hint))
    {
      const double bound = std::min(max_range, (hint - sector.origin).norm());
      const Nearest best = searchSector(map.grid(), sector, bound);
      // A map point in the sector bounds the answer, and the search finds it; anything else (a
      // hint off the map, nothing within max_range) takes the central ray's bound instead.
      if (best.segment >= 0 && best.point.distance <= bound + kPruneSlack)
      {
        return toHit(map.grid().segments(), best, max_range);
      }
    }
  }
  return coneCast(map, sensor, half_angle, max_range);
}

Eigen::RowVector3d coneRangeDerivative(const MapRayCaster& map, const Pose2& sensor, double half_angle,
                                       const ConeHit& hit)
{
  Eigen::RowVector3d out = Eigen::RowVector3d::Zero();
  if (hit.segment < 0 || !(hit.distance > 0.0) || !std::isfinite(hit.distance))
  {
    return out;
  }
  if (hit.side == 0)
  {
    // Strictly inside the sector the nearest point stays the nearest as the sector turns; moving
    // the apex changes its distance along the unit vector to it (the foot slides along the edge,
    // which changes nothing to first order).
    const Vec2 to_point = (hit.point - sensor.position()) / hit.distance;
    out << -to_point.x(), -to_point.y(), 0.0;
    return out;
  }
  // On a bounding ray: the ray cast's derivative, t = n.(a - p) / (n.u).
  const Segment& seg = map.grid().segments()[static_cast<std::size_t>(hit.segment)];
  const Vec2 edge = seg.b - seg.a;
  const double len = edge.norm();
  const double phi = sensor.theta + hit.side * half_angle;
  const Vec2 u(std::cos(phi), std::sin(phi));
  const double nu = len > 0.0 ? cross(edge, u) / len : 0.0;  // n.u with n = edge's left normal
  if (std::abs(nu) < 1e-6)
  {
    return out;
  }
  const Vec2 n(-edge.y() / len, edge.x() / len);
  const Vec2 u_perp(-u.y(), u.x());
  out << -n.x() / nu, -n.y() / nu, -hit.distance * n.dot(u_perp) / nu;
  return out;
}

}  // namespace core
}  // namespace fdml_localization
