// Unit tests of the planar geometry primitives against hand-computed values and an
// independent homogeneous-matrix / Cramer's-rule reference.
#include "fdml_localization/core/geometry/geometry.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
Eigen::Matrix3d matrixOf(const Pose2& p)
{
  Eigen::Matrix3d m;
  m << std::cos(p.theta), -std::sin(p.theta), p.x, std::sin(p.theta), std::cos(p.theta), p.y, 0, 0, 1;
  return m;
}

Pose2 poseOf(const Eigen::Matrix3d& m)
{
  return Pose2(m(0, 2), m(1, 2), std::atan2(m(1, 0), m(0, 0)));
}

void expectPoseNear(const Pose2& a, const Pose2& b, double tol)
{
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(angleDiff(a.theta, b.theta), 0.0, tol);
}

Pose2 randomPose(std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> pos(-20.0, 20.0);
  std::uniform_real_distribution<double> ang(-10.0, 10.0);
  return Pose2(pos(rng), pos(rng), ang(rng));
}

/// Reference ray/segment distance in long double for a segment not parallel to the ray.
long double referenceDistance(const Vec2& o, const Vec2& d, const Segment& s)
{
  // o + t d = a + u (b - a)  ->  [d, a - b] [t u]^T = a - o
  const long double ex = s.b.x() - s.a.x(), ey = s.b.y() - s.a.y();
  const long double det = static_cast<long double>(d.x()) * -ey - static_cast<long double>(d.y()) * -ex;
  const long double rx = s.a.x() - o.x(), ry = s.a.y() - o.y();
  const long double t = (rx * -ey - ry * -ex) / det;
  const long double u = (d.x() * ry - d.y() * rx) / det;
  if (t < 0 || u < 0 || u > 1)
  {
    return INFINITY;
  }
  return t;
}
}  // namespace

TEST(Geometry, WrapAngleRange)
{
  EXPECT_DOUBLE_EQ(wrapAngle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(wrapAngle(1.0), 1.0);
  EXPECT_DOUBLE_EQ(wrapAngle(-1.0), -1.0);
  EXPECT_DOUBLE_EQ(wrapAngle(-kPi), -kPi);
  EXPECT_DOUBLE_EQ(wrapAngle(kPi), -kPi);  // [-pi, pi): +pi maps to -pi
  EXPECT_NEAR(wrapAngle(kTwoPi + 0.5), 0.5, 1e-12);
  EXPECT_NEAR(wrapAngle(-kTwoPi - 0.5), -0.5, 1e-12);
  EXPECT_NEAR(wrapAngle(3.0 * kPi / 2.0), -kPi / 2.0, 1e-12);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> any(-1000.0, 1000.0);
  for (int i = 0; i < 10000; ++i)
  {
    const double a = any(rng);
    const double w = wrapAngle(a);
    ASSERT_GE(w, -kPi);
    ASSERT_LT(w, kPi);
    // Same direction: the difference is a whole number of turns.
    const double turns = (a - w) / kTwoPi;
    ASSERT_NEAR(turns, std::round(turns), 1e-9) << a;
  }
}

TEST(Geometry, AngleDiff)
{
  EXPECT_NEAR(angleDiff(0.1, -0.1), 0.2, 1e-15);
  EXPECT_NEAR(angleDiff(kPi - 0.1, -kPi + 0.1), -0.2, 1e-12);
  EXPECT_NEAR(angleDiff(-kPi + 0.1, kPi - 0.1), 0.2, 1e-12);
  EXPECT_NEAR(angleDiff(5.0 * kTwoPi + 1.0, 1.0), 0.0, 1e-12);
}

TEST(Geometry, ComposeMatchesMatrices)
{
  const Pose2 a(1.0, 2.0, kPi / 2.0);
  const Pose2 b(3.0, 0.0, 0.0);
  const Pose2 c = compose(a, b);
  EXPECT_NEAR(c.x, 1.0, 1e-12);
  EXPECT_NEAR(c.y, 5.0, 1e-12);
  EXPECT_NEAR(c.theta, kPi / 2.0, 1e-12);

  std::mt19937_64 rng(11);
  for (int i = 0; i < 2000; ++i)
  {
    const Pose2 p = randomPose(rng), q = randomPose(rng);
    const Pose2 r = compose(p, q);
    expectPoseNear(r, poseOf(matrixOf(p) * matrixOf(q)), 1e-9);
    ASSERT_GE(r.theta, -kPi);
    ASSERT_LT(r.theta, kPi);
  }
}

TEST(Geometry, InverseAndBetween)
{
  std::mt19937_64 rng(12);
  for (int i = 0; i < 2000; ++i)
  {
    const Pose2 a = randomPose(rng), b = randomPose(rng);
    expectPoseNear(compose(a, inverse(a)), Pose2(0, 0, 0), 1e-9);
    expectPoseNear(compose(inverse(a), a), Pose2(0, 0, 0), 1e-9);
    expectPoseNear(inverse(a), poseOf(matrixOf(a).inverse()), 1e-9);
    expectPoseNear(compose(a, between(a, b)), b, 1e-9);
  }
}

TEST(Geometry, TransformPoint)
{
  const Vec2 p = transformPoint(Pose2(1.0, -1.0, kPi), Vec2(2.0, 0.5));
  EXPECT_NEAR(p.x(), -1.0, 1e-12);
  EXPECT_NEAR(p.y(), -1.5, 1e-12);
  std::mt19937_64 rng(13);
  for (int i = 0; i < 1000; ++i)
  {
    const Pose2 a = randomPose(rng);
    const Vec2 v(a.y, a.x);
    const Eigen::Vector3d ref = matrixOf(a) * Eigen::Vector3d(v.x(), v.y(), 1.0);
    const Vec2 got = transformPoint(a, v);
    ASSERT_NEAR(got.x(), ref.x(), 1e-9);
    ASSERT_NEAR(got.y(), ref.y(), 1e-9);
  }
}

TEST(Geometry, RaySegmentDistanceCases)
{
  const Segment vertical{ Vec2(2.0, -1.0), Vec2(2.0, 1.0) };
  const Vec2 o(0.0, 0.0);
  EXPECT_NEAR(raySegmentDistance(o, Vec2(1, 0), vertical), 2.0, 1e-15);
  EXPECT_EQ(raySegmentDistance(o, Vec2(-1, 0), vertical), kInf);  // behind
  EXPECT_EQ(raySegmentDistance(o, Vec2(0, 1), vertical), kInf);   // parallel, apart
  const Vec2 diag = Vec2(1.0, 0.5).normalized();
  EXPECT_NEAR(raySegmentDistance(o, diag, vertical), std::sqrt(5.0), 1e-12);  // through endpoint
  const Vec2 steep = Vec2(1.0, 0.6).normalized();
  EXPECT_EQ(raySegmentDistance(o, steep, { Vec2(2.0, -1.0), Vec2(2.0, 1.1) }), kInf);  // just past the end
  // Collinear: hits the nearest point of the segment.
  const Segment horizontal{ Vec2(3.0, 0.0), Vec2(5.0, 0.0) };
  EXPECT_NEAR(raySegmentDistance(o, Vec2(1, 0), horizontal), 3.0, 1e-15);
  EXPECT_NEAR(raySegmentDistance(Vec2(6.0, 0.0), Vec2(-1, 0), horizontal), 1.0, 1e-15);
  EXPECT_NEAR(raySegmentDistance(Vec2(4.0, 0.0), Vec2(1, 0), horizontal), 0.0, 1e-15);  // starts on it
  EXPECT_EQ(raySegmentDistance(o, Vec2(-1, 0), horizontal), kInf);                      // collinear, behind
  // Collinear from an endpoint, pointing away from the segment: the origin is on it (0, not -2).
  EXPECT_EQ(raySegmentDistance(Vec2(5.0, 0.0), Vec2(1, 0), horizontal), 0.0);
  EXPECT_EQ(raySegmentDistance(Vec2(3.0, 0.0), Vec2(-1, 0), horizontal), 0.0);
  EXPECT_EQ(raySegmentDistance(Vec2(3.0, 0.0), Vec2(1, 0), horizontal), 0.0);
  // Origin on a crossing segment.
  EXPECT_NEAR(raySegmentDistance(Vec2(2.0, 0.3), Vec2(1, 0), vertical), 0.0, 1e-15);
}

TEST(Geometry, RaySegmentDistanceMatchesReference)
{
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> pos(-5.0, 5.0);
  std::uniform_real_distribution<double> ang(-kPi, kPi);
  int hits = 0;
  for (int i = 0; i < 20000; ++i)
  {
    const Vec2 o(pos(rng), pos(rng));
    const double a = ang(rng);
    const Vec2 d(std::cos(a), std::sin(a));
    const Segment s{ Vec2(pos(rng), pos(rng)), Vec2(pos(rng), pos(rng)) };
    const Vec2 e = s.b - s.a;
    const double sin_angle = std::abs(d.x() * e.y() - d.y() * e.x()) / e.norm();
    if (sin_angle < 1e-3)
    {
      continue;  // near-parallel: covered by the explicit cases
    }
    const long double ref = referenceDistance(o, d, s);
    const double got = raySegmentDistance(o, d, s);
    if (std::isinf(static_cast<double>(ref)))
    {
      // Only at the segment's ends or at the origin may rounding turn a miss into a hit.
      if (std::isfinite(got))
      {
        const Vec2 p = o + got * d;
        ASSERT_LT(pointSegmentDistanceSquared(p, s), 1e-18) << i;
        ASSERT_TRUE(std::min((p - s.a).norm(), (p - s.b).norm()) < 1e-9 || got < 1e-9) << i;
      }
      continue;
    }
    ++hits;
    ASSERT_NEAR(got, static_cast<double>(ref), 1e-9 * (1.0 + static_cast<double>(ref))) << i;
  }
  EXPECT_GT(hits, 2000);
}

TEST(Geometry, RayCircleDistance)
{
  const Vec2 c(3.0, 0.0);
  EXPECT_NEAR(rayCircleDistance(Vec2(0, 0), Vec2(1, 0), c, 1.0), 2.0, 1e-12);
  EXPECT_EQ(rayCircleDistance(Vec2(0, 0), Vec2(-1, 0), c, 1.0), kInf);
  EXPECT_EQ(rayCircleDistance(Vec2(0, 0), Vec2(0, 1), c, 1.0), kInf);
  EXPECT_EQ(rayCircleDistance(Vec2(3.0, 0.5), Vec2(1, 0), c, 1.0), 0.0);  // inside
  // Tangent-ish ray at 45 degrees: distance to the chord's near point.
  const Vec2 d = Vec2(1.0, 1.0).normalized();
  const double t = rayCircleDistance(Vec2(2.0, -1.0), d, c, 1.0);
  EXPECT_NEAR(((Vec2(2.0, -1.0) + t * d) - c).norm(), 1.0, 1e-12);
}

TEST(Geometry, SegmentsAndBoxes)
{
  EXPECT_TRUE(segmentsIntersect({ Vec2(0, 0), Vec2(2, 2) }, { Vec2(0, 2), Vec2(2, 0) }));
  EXPECT_FALSE(segmentsIntersect({ Vec2(0, 0), Vec2(1, 1) }, { Vec2(0, 2), Vec2(0.9, 1.1) }));
  EXPECT_TRUE(segmentsIntersect({ Vec2(0, 0), Vec2(1, 0) }, { Vec2(1, 0), Vec2(1, 3) }));   // touch at end
  EXPECT_TRUE(segmentsIntersect({ Vec2(0, 0), Vec2(2, 0) }, { Vec2(1, 0), Vec2(3, 0) }));   // overlap
  EXPECT_FALSE(segmentsIntersect({ Vec2(0, 0), Vec2(1, 0) }, { Vec2(2, 0), Vec2(3, 0) }));  // collinear gap
  Box2 box;
  box.extend(Vec2(0, 0));
  box.extend(Vec2(1, 1));
  EXPECT_TRUE(segmentIntersectsBox({ Vec2(-1, 0.5), Vec2(2, 0.5) }, box));
  EXPECT_TRUE(segmentIntersectsBox({ Vec2(0.2, 0.2), Vec2(0.3, 0.3) }, box));  // inside
  EXPECT_TRUE(segmentIntersectsBox({ Vec2(1, 2), Vec2(1, 1) }, box));          // touches a corner
  EXPECT_FALSE(segmentIntersectsBox({ Vec2(1.5, 0), Vec2(3, 1) }, box));
  EXPECT_FALSE(segmentIntersectsBox({ Vec2(-1, 0.6), Vec2(0.6, 2.2) }, box));  // passes the corner
  EXPECT_NEAR(pointSegmentDistanceSquared(Vec2(0, 1), { Vec2(-1, 0), Vec2(1, 0) }), 1.0, 1e-15);
  EXPECT_NEAR(pointSegmentDistanceSquared(Vec2(3, 1), { Vec2(-1, 0), Vec2(1, 0) }), 5.0, 1e-15);
}

TEST(Geometry, RingsAreaAndInside)
{
  const Ring square{ Vec2(0, 0), Vec2(2, 0), Vec2(2, 2), Vec2(0, 2) };
  EXPECT_NEAR(signedArea(square), 4.0, 1e-15);
  const Ring reversed(square.rbegin(), square.rend());
  EXPECT_NEAR(signedArea(reversed), -4.0, 1e-15);
  const Ring l_shape{ Vec2(0, 0), Vec2(4, 0), Vec2(4, 1), Vec2(1, 1), Vec2(1, 3), Vec2(0, 3) };
  EXPECT_NEAR(signedArea(l_shape), 6.0, 1e-15);
  EXPECT_TRUE(pointInRing(Vec2(0.5, 2.5), l_shape));
  EXPECT_TRUE(pointInRing(Vec2(3.5, 0.5), l_shape));
  EXPECT_FALSE(pointInRing(Vec2(2.5, 2.5), l_shape));
  EXPECT_FALSE(pointInRing(Vec2(-0.5, 0.5), l_shape));
  EXPECT_TRUE(pointInRing(Vec2(0.5, 2.5), Ring(l_shape.rbegin(), l_shape.rend())));
}

}  // namespace core
}  // namespace fdml_localization
