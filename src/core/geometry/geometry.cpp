#include "fdml_localization/core/geometry/geometry.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace core
{
double wrapAngle(double angle)
{
  if (!std::isfinite(angle))
  {
    return angle;
  }
  double a = std::fmod(angle + kPi, kTwoPi);
  if (a < 0.0)
  {
    a += kTwoPi;
  }
  a -= kPi;
  // fmod can round up to exactly +pi; keep the half-open interval.
  return a >= kPi ? -kPi : a;
}

double angleDiff(double a, double b)
{
  return wrapAngle(a - b);
}

Pose2 compose(const Pose2& a, const Pose2& b)
{
  const double c = std::cos(a.theta);
  const double s = std::sin(a.theta);
  return Pose2(a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, wrapAngle(a.theta + b.theta));
}

Pose2 inverse(const Pose2& a)
{
  const double c = std::cos(a.theta);
  const double s = std::sin(a.theta);
  return Pose2(-c * a.x - s * a.y, s * a.x - c * a.y, wrapAngle(-a.theta));
}

Pose2 between(const Pose2& a, const Pose2& b)
{
  return compose(inverse(a), b);
}

Eigen::Vector3d poseDifference(const Pose2& a, const Pose2& b)
{
  return Eigen::Vector3d(a.x - b.x, a.y - b.y, angleDiff(a.theta, b.theta));
}

Vec2 transformPoint(const Pose2& a, const Vec2& p)
{
  const double c = std::cos(a.theta);
  const double s = std::sin(a.theta);
  return Vec2(a.x + c * p.x() - s * p.y(), a.y + s * p.x() + c * p.y());
}

double rayParallelSegmentDistance(const Vec2& origin, const Vec2& dir, const Segment& seg)
{
  // A hit only when collinear, then at the nearest point ahead of the origin.
  const Vec2 w = seg.a - origin;
  if (std::abs(cross(w, dir)) > 1e-12 * std::max(1.0, w.norm()))
  {
    return kInf;
  }
  const double ta = w.dot(dir);
  const double tb = (seg.b - origin).dot(dir);
  if (ta < 0.0 && tb < 0.0)
  {
    return kInf;
  }
  if (ta <= 0.0 || tb <= 0.0)
  {
    return 0.0;  // the origin lies on the segment (possibly at an endpoint)
  }
  return std::min(ta, tb);
}

double rayCircleDistance(const Vec2& origin, const Vec2& dir, const Vec2& centre, double radius)
{
  const Vec2 m = origin - centre;
  const double c = m.squaredNorm() - radius * radius;
  if (c <= 0.0)
  {
    return 0.0;
  }
  const double b = m.dot(dir);
  if (b > 0.0)
  {
    return kInf;
  }
  const double disc = b * b - c;
  if (disc < 0.0)
  {
    return kInf;
  }
  return -b - std::sqrt(disc);
}

bool segmentIntersectsBox(const Segment& seg, const Box2& box)
{
  // Liang-Barsky clipping of the segment against the closed box.
  double t0 = 0.0;
  double t1 = 1.0;
  const Vec2 d = seg.b - seg.a;
  for (int axis = 0; axis < 2; ++axis)
  {
    const double p = seg.a[axis];
    const double lo = box.min[axis];
    const double hi = box.max[axis];
    if (d[axis] == 0.0)
    {
      if (p < lo || p > hi)
      {
        return false;
      }
      continue;
    }
    double ta = (lo - p) / d[axis];
    double tb = (hi - p) / d[axis];
    if (ta > tb)
    {
      std::swap(ta, tb);
    }
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1)
    {
      return false;
    }
  }
  return true;
}

namespace
{
int orientation(const Vec2& a, const Vec2& b, const Vec2& c)
{
  const double v = cross(b - a, c - a);
  return (v > 0.0) - (v < 0.0);
}

bool onSegment(const Vec2& a, const Vec2& b, const Vec2& p)
{
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) && p.y() >= std::min(a.y(), b.y()) &&
         p.y() <= std::max(a.y(), b.y());
}
}  // namespace

bool segmentsIntersect(const Segment& s, const Segment& t)
{
  const int o1 = orientation(s.a, s.b, t.a);
  const int o2 = orientation(s.a, s.b, t.b);
  const int o3 = orientation(t.a, t.b, s.a);
  const int o4 = orientation(t.a, t.b, s.b);
  if (o1 != o2 && o3 != o4)
  {
    return true;
  }
  return (o1 == 0 && onSegment(s.a, s.b, t.a)) || (o2 == 0 && onSegment(s.a, s.b, t.b)) ||
         (o3 == 0 && onSegment(t.a, t.b, s.a)) || (o4 == 0 && onSegment(t.a, t.b, s.b));
}

Vec2 closestPointOnSegment(const Vec2& p, const Segment& seg)
{
  const Vec2 e = seg.b - seg.a;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - seg.a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return seg.a + t * e;
}

double pointSegmentDistanceSquared(const Vec2& p, const Segment& seg)
{
  return (closestPointOnSegment(p, seg) - p).squaredNorm();
}

double horizontalCrossingX(double y, const Vec2& a, const Vec2& b)
{
  if ((a.y() > y) == (b.y() > y))
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  // Canonical order (lower y first) so that the result does not depend on the edge's direction.
  const Vec2& lo = a.y() < b.y() ? a : b;
  const Vec2& hi = a.y() < b.y() ? b : a;
  return lo.x() + (y - lo.y()) * (hi.x() - lo.x()) / (hi.y() - lo.y());
}

bool crossesRightOf(const Vec2& p, const Vec2& a, const Vec2& b)
{
  return p.x() < horizontalCrossingX(p.y(), a, b);  // false for NaN
}

Crossing segmentCrossing(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b, double tolerance)
{
  // Each orientation is a signed distance times the length of the segment it is taken against.
  const double ab = (b - a).norm();
  const double pq = (q - p).norm();
  const double o1 = cross(b - a, p - a);
  const double o2 = cross(b - a, q - a);
  const double o3 = cross(q - p, a - p);
  const double o4 = cross(q - p, b - p);
  if (std::abs(o1) <= tolerance * ab || std::abs(o2) <= tolerance * ab || std::abs(o3) <= tolerance * pq ||
      std::abs(o4) <= tolerance * pq)
  {
    // An end near the other's line: degenerate when their boxes, grown by the tolerance, meet.
    const bool apart = std::max(p.x(), q.x()) + tolerance < std::min(a.x(), b.x()) ||
                       std::max(a.x(), b.x()) + tolerance < std::min(p.x(), q.x()) ||
                       std::max(p.y(), q.y()) + tolerance < std::min(a.y(), b.y()) ||
                       std::max(a.y(), b.y()) + tolerance < std::min(p.y(), q.y());
    return apart ? Crossing::None : Crossing::Degenerate;
  }
  return ((o1 > 0.0) != (o2 > 0.0) && (o3 > 0.0) != (o4 > 0.0)) ? Crossing::Proper : Crossing::None;
}

bool pointInRing(const Vec2& p, const Ring& ring)
{
  bool inside = false;
  const std::size_t n = ring.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
  {
    if (crossesRightOf(p, ring[i], ring[j]))
    {
      inside = !inside;
    }
  }
  return inside;
}

double signedArea(const Ring& ring)
{
  double twice = 0.0;
  const std::size_t n = ring.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++)
  {
    twice += cross(ring[j], ring[i]);
  }
  return 0.5 * twice;
}

}  // namespace core
}  // namespace fdml_localization
