// Where the cone cast finds its nearest point (coneCast) and the analytic derivative of the cone
// range (coneRangeDerivative) used by the polish: the point lies on its edge at the cast's
// distance, inside the sector or on the bounding ray its side names; a hint (the polish's last
// hit point) never changes the answer; the derivative matches central differences of the exact
// cone cast wherever the cast is smooth.
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/map/map_io.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

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

double pointSegmentDistance(const Vec2& p, const Segment& s)
{
  const Vec2 e = s.b - s.a;
  const double t = e.squaredNorm() > 0.0 ? std::clamp((p - s.a).dot(e) / e.squaredNorm(), 0.0, 1.0) : 0.0;
  return (s.a + t * e - p).norm();
}

/// Random free sensor poses of a bundled map with a half-angle in [0, 0.6] (a = 0 one in five).
template <typename Check>
void forRandomCones(int count, std::uint64_t seed, Check check)
{
  std::mt19937_64 rng(seed);
  for (const std::string& path : test::bundledMaps())
  {
    const MapRayCaster map(loadPolyFile(path));
    const Box2 b = map.grid().bounds();
    std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()), ut(-kPi, kPi),
        ua(0.0, 0.6);
    for (int checked = 0; checked < count;)
    {
      const Pose2 sensor(ux(rng), uy(rng), ut(rng));
      if (map.isFree(sensor.position()))
      {
        ++checked;
        check(map, sensor, checked % 5 == 0 ? 0.0 : ua(rng), path);
      }
    }
  }
}

TEST(ConeCastHit, ThePointLiesOnItsEdgeAtTheDistanceAndOnTheNamedSide)
{
  forRandomCones(300, 5, [](const MapRayCaster& map, const Pose2& sensor, double a, const std::string& path) {
    const ConeHit hit = coneCast(map, sensor, a);
    ASSERT_EQ(hit.distance, coneRange(map, sensor, a)) << path;
    ASSERT_GE(hit.segment, 0) << path;
    const Vec2 o = sensor.position();
    EXPECT_NEAR((hit.point - o).norm(), hit.distance, 1e-9) << path;
    EXPECT_LT(pointSegmentDistance(hit.point, map.grid().segments()[static_cast<std::size_t>(hit.segment)]), 1e-9);
    const Vec2 right = test::unitDir(sensor.theta - a);
    const Vec2 left = test::unitDir(sensor.theta + a);
    EXPECT_GE(cross(right, hit.point - o), -1e-9) << path;
    EXPECT_LE(cross(left, hit.point - o), 1e-9) << path;
    if (hit.side != 0)
    {
      EXPECT_NEAR(cross(hit.side > 0 ? left : right, hit.point - o), 0.0, 1e-9) << path << " a " << a;
    }
  });
}

TEST(ConeCastHint, AnyHintGivesTheSameAnswer)
{
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> jitter(-0.05, 0.05);
  int bounded = 0;
  forRandomCones(300, 7, [&](const MapRayCaster& map, const Pose2& sensor, double a, const std::string& path) {
    const ConeHit exact = coneCast(map, sensor, a);
    // A map point from a nearby pose (the polish's hint), a point off the map's edges, and none.
    const Pose2 near(sensor.x + jitter(rng), sensor.y + jitter(rng), sensor.theta + jitter(rng));
    const Vec2 off_edge = sensor.position() + 0.3 * exact.distance * sensor.heading();
    for (const Vec2& hint : { coneCast(map, near, a).point, off_edge, Vec2(kInf, 0.0) })
    {
      for (const double max_range : { kInf, 0.8 * exact.distance })
      {
        const ConeHit hinted = coneCast(map, sensor, a, max_range, hint);
        ASSERT_EQ(hinted.distance, coneRange(map, sensor, a, max_range)) << path << " a " << a;
        ASSERT_EQ(hinted.segment < 0, std::isinf(hinted.distance)) << path;
      }
    }
    bounded += Sector::around(sensor, a).contains(coneCast(map, near, a).point) ? 1 : 0;
  });
  EXPECT_GT(bounded, 300);  // the nearby pose's hit bounds the search often
}

TEST(ConeRangeDerivative, MatchesCentralDifferencesWhereTheCastIsSmooth)
{
  constexpr double kStep = 1e-6;
  int compared = 0;
  int total = 0;
  forRandomCones(300, 6, [&](const MapRayCaster& map, const Pose2& sensor, double a, const std::string& path) {
    ++total;
    const ConeHit hit = coneCast(map, sensor, a);
    const Eigen::RowVector3d analytic = coneRangeDerivative(map, sensor, a, hit);
    for (int axis = 0; axis < 3; ++axis)
    {
      const auto shifted = [&](double h) {
        return coneRange(map,
                         Pose2(sensor.x + (axis == 0 ? h : 0.0), sensor.y + (axis == 1 ? h : 0.0),
                               sensor.theta + (axis == 2 ? h : 0.0)),
                         a);
      };
      const double forward = (shifted(kStep) - hit.distance) / kStep;
      const double backward = (hit.distance - shifted(-kStep)) / kStep;
      // A kink (the nearest point jumps to another edge, or between inside and a bounding ray)
      // has no derivative: compare only where both one-sided differences agree.
      if (std::abs(forward - backward) > 1e-4 * (1.0 + std::abs(forward)))
      {
        continue;
      }
      ++compared;
      EXPECT_NEAR(analytic(axis), 0.5 * (forward + backward), 1e-4 * (1.0 + std::abs(forward)))
          << path << " axis " << axis << " a " << a << " side " << hit.side;
    }
  });
  EXPECT_GT(compared, 3 * total * 9 / 10);  // the cast is smooth almost everywhere
}

TEST(ConeRangeDerivative, FacingAWallTheHeadingDoesNotChangeTheRange)
{
  // A wall at x = 2; a sensor at the origin heading 0.2 rad with a half-angle of 0.5: the foot of
  // the perpendicular (2, 0) lies inside the sector.
  const MapRayCaster map(PolygonMap::fromRings({ { Vec2(-1, -3), Vec2(2, -3), Vec2(2, 3), Vec2(-1, 3) } }, "wall"));
  const Pose2 sensor(0.0, 0.0, 0.2);
  const ConeHit hit = coneCast(map, sensor, 0.5);
  EXPECT_EQ(hit.side, 0);
  EXPECT_NEAR(hit.distance, 2.0, 1e-12);
  const Eigen::RowVector3d d = coneRangeDerivative(map, sensor, 0.5, hit);
  EXPECT_NEAR(d(0), -1.0, 1e-12);
  EXPECT_NEAR(d(1), 0.0, 1e-12);
  EXPECT_EQ(d(2), 0.0);
  // A narrower cone misses the foot: its right bounding ray hits the wall, and the heading matters.
  const ConeHit ray_hit = coneCast(map, sensor, 0.1);
  EXPECT_EQ(ray_hit.side, -1);
  EXPECT_NEAR(ray_hit.distance, 2.0 / std::cos(0.1), 1e-12);
  EXPECT_NEAR(coneRangeDerivative(map, sensor, 0.1, ray_hit)(2), 2.0 * std::sin(0.1) / std::pow(std::cos(0.1), 2),
              1e-9);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
