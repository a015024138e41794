/**
 * @file geometry.h
 * @brief Planar geometry primitives shared by the whole core: points, poses on
 *        SE(2), segments and boxes. Units: metres [m] and radians [rad], REP-103.
 */
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A point or vector in the plane [m].
using Vec2 = Eigen::Vector2d;

/// A closed ring of vertices (the closing edge from back() to front() is implicit).
using Ring = std::vector<Vec2>;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// Wraps an angle [rad] to [-pi, pi).
double wrapAngle(double angle);

/// The signed smallest difference a - b wrapped to [-pi, pi) [rad].
double angleDiff(double a, double b);

/// A pose on SE(2): position x, y [m] and heading theta [rad] (counter-clockwise from +x).
struct Pose2
{
  double x = 0.0;
  double y = 0.0;
  double theta = 0.0;

  Pose2() = default;
  Pose2(double x_in, double y_in, double theta_in) : x(x_in), y(y_in), theta(theta_in)
  {}

  Vec2 position() const
  {
    return Vec2(x, y);
  }
  /// Unit vector along the pose's +x axis.
  Vec2 heading() const
  {
    return Vec2(std::cos(theta), std::sin(theta));
  }
};

/// Composition a (+) b: the pose b, expressed in frame a, moved into a's parent frame.
/// The result's angle is wrapped to [-pi, pi).
Pose2 compose(const Pose2& a, const Pose2& b);

/// The inverse pose: compose(a, inverse(a)) is the identity.
Pose2 inverse(const Pose2& a);

/// The relative pose inverse(a) (+) b: b expressed in frame a.
Pose2 between(const Pose2& a, const Pose2& b);

/// The difference a - b of two poses as a vector (x, y, heading wrapped to (-pi, pi]) [m, m, rad],
/// in the map frame: what a covariance of (x, y, theta) weighs (not between()).
Eigen::Vector3d poseDifference(const Pose2& a, const Pose2& b);

/// Applies pose a to a point p given in frame a [m].
Vec2 transformPoint(const Pose2& a, const Vec2& p);

/// A line segment from a to b [m].
struct Segment
{
  Vec2 a;
  Vec2 b;
};

/// An axis-aligned box [m]. Empty when min > max in either axis.
struct Box2
{
  Vec2 min = Vec2(kInf, kInf);
  Vec2 max = Vec2(-kInf, -kInf);

  bool empty() const
  {
    return min.x() > max.x() || min.y() > max.y();
  }
  void extend(const Vec2& p)
  {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void extend(const Box2& b)
  {
    min = min.cwiseMin(b.min);
    max = max.cwiseMax(b.max);
  }
  Vec2 size() const
  {
    return max - min;
  }
  bool contains(const Vec2& p) const
  {
    return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y();
  }
  bool intersects(const Box2& b) const
  {
    return !(b.min.x() > max.x() || b.max.x() < min.x() || b.min.y() > max.y() || b.max.y() < min.y());
  }
};

/// z component of the cross product a x b.
inline double cross(const Vec2& a, const Vec2& b)
{
  return a.x() * b.y() - a.y() * b.x();
}

/// raySegmentDistance() for a ray parallel to the segment (|dir x e| <= 1e-14 |e|, e = b - a).
double rayParallelSegmentDistance(const Vec2& origin, const Vec2& dir, const Segment& seg);

/**
 * @brief Distance along a ray to a segment.
 * @param origin ray origin [m]
 * @param dir unit direction of the ray
 * @param seg the segment
 * @return the smallest t >= 0 with origin + t dir on the segment [m], or +inf when the ray
 *         misses it. A ray collinear with the segment hits it at its nearest point.
 */
inline double raySegmentDistance(const Vec2& origin, const Vec2& dir, const Segment& seg)
{
  // Inline: the innermost loop of every ray cast.
  const Vec2 e = seg.b - seg.a;
  const Vec2 w = seg.a - origin;
  const double denom = cross(dir, e);
  // Parallel when |dir x e| <= 1e-14 |e| (compared squared: no square root on the hot path).
  if (denom * denom <= 1e-28 * e.squaredNorm())
  {
    return rayParallelSegmentDistance(origin, dir, seg);
  }
  const double t = cross(w, e) / denom;    // along the ray
  const double u = cross(w, dir) / denom;  // along the segment, in [0, 1] on it
  const double tol = 1e-12;
  if (t < -tol || u < -tol || u > 1.0 + tol)
  {
    return kInf;
  }
  return std::max(t, 0.0);
}

/// Distance along a ray to a circle's boundary [m] (+inf on a miss; 0 when the origin is inside).
double rayCircleDistance(const Vec2& origin, const Vec2& dir, const Vec2& centre, double radius);

/// True when the segment touches the box (closed sets).
bool segmentIntersectsBox(const Segment& seg, const Box2& box);

/// True when the two closed segments share a point.
bool segmentsIntersect(const Segment& s, const Segment& t);

/// The point of a segment nearest to p (its first end for a degenerate segment).
Vec2 closestPointOnSegment(const Vec2& p, const Segment& seg);

/// Squared distance from point p to a segment [m^2].
double pointSegmentDistanceSquared(const Vec2& p, const Segment& seg);

/// True when the horizontal half-line from p towards +x crosses the edge a-b (half-open in y,
/// so a vertex on the line is counted once). Symmetric in a and b.
bool crossesRightOf(const Vec2& p, const Vec2& a, const Vec2& b);

/// Where the horizontal line at height @p y [m] crosses the edge a-b under crossesRightOf's
/// half-open rule: its x [m], or NaN when it does not cross (crossesRightOf(p, a, b) is
/// p.x() < horizontalCrossingX(p.y(), a, b)).
double horizontalCrossingX(double y, const Vec2& a, const Vec2& b);

/// How two closed segments meet, for a parity walk along the first one.
enum class Crossing
{
  None,       ///< disjoint, clearly
  Proper,     ///< they cross at one point interior to both, clearly
  Degenerate  ///< an end lies on (or within @p tolerance of) the other's line
};

/**
 * @brief Whether segment p-q crosses edge a-b, with a margin: Degenerate when an end of either
 *        lies within @p tolerance [m] of the other's line (touching, collinear, or too near to
 *        tell in floating point), so that a caller may fall back to a rule that settles those.
 */
Crossing segmentCrossing(const Vec2& p, const Vec2& q, const Vec2& a, const Vec2& b, double tolerance);

/// Crossing-number point-in-ring test (points exactly on the boundary may go either way).
bool pointInRing(const Vec2& p, const Ring& ring);

/// Signed area of a ring [m^2]: positive when counter-clockwise.
double signedArea(const Ring& ring);

}  // namespace core
}  // namespace fdml_localization
