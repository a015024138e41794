// The exact cone cast against two independent references: the minimum over the candidate points
// of the statement (edge endpoints inside the sector, perpendicular feet inside it, the
// hits of its two bounding rays) with sector membership by angle, and a dense fan of rays, which
// can only be longer than the sector's nearest point and comes within the fan's chord error.
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/map_generators.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
double fanMinimum(const SegmentGrid& grid, const Pose2& sensor, double half_angle, double max_range, int rays)
{
  double best = kInf;
  for (int i = 0; i <= rays; ++i)
  {
    const double phi = sensor.theta - half_angle + 2.0 * half_angle * i / rays;
    best = std::min(best, grid.castBruteForce(sensor.position(), test::unitDir(phi), max_range).distance);
  }
  return best;
}

bool inSectorByAngle(const Pose2& sensor, double half_angle, const Vec2& p)
{
  const Vec2 v = p - sensor.position();
  return v.squaredNorm() == 0.0 || std::abs(angleDiff(std::atan2(v.y(), v.x()), sensor.theta)) <= half_angle + 1e-12;
}

/// The nearest point of a segment inside a sector is an endpoint, the perpendicular foot, or a
/// bounding ray's hit: the minimum over those candidates that lie in the sector.
double candidateMinimum(const std::vector<Segment>& segments, const Pose2& sensor, double half_angle, double max_range)
{
  const Vec2 o = sensor.position();
  double best = kInf;
  auto consider = [&](const Vec2& p) {
    if (inSectorByAngle(sensor, half_angle, p))
    {
      best = std::min(best, (p - o).norm());
    }
  };
  for (const Segment& s : segments)
  {
    consider(s.a);
    consider(s.b);
    const Vec2 e = s.b - s.a;
    const double t = e.squaredNorm() > 0.0 ? (o - s.a).dot(e) / e.squaredNorm() : 0.0;
    if (t > 0.0 && t < 1.0)
    {
      consider(s.a + t * e);
    }
    for (const double side : { -1.0, 1.0 })
    {
      best = std::min(best, raySegmentDistance(o, test::unitDir(sensor.theta + side * half_angle), s));
    }
  }
  return best <= max_range ? best : kInf;
}

std::vector<std::pair<std::string, PolygonMap>> testMaps()
{
  std::vector<std::pair<std::string, PolygonMap>> maps;
  for (const std::string& path : test::bundledMaps())
  {
    maps.emplace_back(test::baseName(path), loadPolyFile(path));
  }
  for (const std::uint64_t seed : { 11, 12, 13 })
  {
    maps.emplace_back("random40 seed " + std::to_string(seed), randomPolygon(40, 3.0, 0.8, seed));
  }
  return maps;
}

TEST(ConeCast, MatchesCandidatePointsOnRandomPosesAndMaps)
{
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> ut(-kPi, kPi);
  std::uniform_real_distribution<double> ua(0.0, kMaxConeHalfAngle);
  for (const auto& [name, polygon_map] : testMaps())
  {
    const MapRayCaster map(polygon_map);
    const Box2 bounds = map.grid().bounds();
    std::uniform_real_distribution<double> ux(bounds.min.x(), bounds.max.x());
    std::uniform_real_distribution<double> uy(bounds.min.y(), bounds.max.y());
    for (int checked = 0; checked < 400;)
    {
      const Pose2 sensor(ux(rng), uy(rng), ut(rng));
      if (!map.isFree(sensor.position()))
      {
        continue;
      }
      ++checked;
      const double a = checked % 4 == 0 ? kMaxConeHalfAngle : ua(rng);
      const double max_range = checked % 3 == 0 ? 1.5 : kInf;
      const double cone = coneRange(map, sensor, a, max_range);
      EXPECT_EQ(cone, coneRangeBruteForce(map.grid().segments(), sensor, a, max_range)) << name;
      const double reference = candidateMinimum(map.grid().segments(), sensor, a, max_range);
      if (std::isinf(reference))
      {
        EXPECT_TRUE(std::isinf(cone)) << name << " a " << a;
      }
      else
      {
        EXPECT_NEAR(cone, reference, 1e-9) << name << " a " << a;
      }
      // The nearest point of the sector is never farther than its central ray's hit, and a wider
      // sector sees at least as near.
      EXPECT_LE(cone, map.range(sensor, max_range)) << name;
      EXPECT_LE(cone, coneRange(map, sensor, 0.5 * a, max_range)) << name;
    }
  }
}

TEST(ConeCast, MatchesDenseFanOfRays)
{
  std::mt19937 rng(7);
  for (const std::string& path : test::bundledMaps())
  {
    const MapRayCaster map(loadPolyFile(path));
    const Box2 bounds = map.grid().bounds();
    std::uniform_real_distribution<double> ux(bounds.min.x(), bounds.max.x());
    std::uniform_real_distribution<double> uy(bounds.min.y(), bounds.max.y());
    std::uniform_real_distribution<double> ut(-kPi, kPi);
    std::uniform_real_distribution<double> ua(0.0, 0.3);
    int checked = 0;
    int close = 0;
    while (checked < 200)
    {
      const Pose2 sensor(ux(rng), uy(rng), ut(rng));
      if (!map.isFree(sensor.position()))
      {
        continue;
      }
      ++checked;
      const double a = ua(rng);
      const double max_range = (checked % 3 == 0) ? 2.0 : kInf;
      const double cone = coneRange(map, sensor, a, max_range);
      const double fan = fanMinimum(map.grid(), sensor, a, max_range, 2000);
      if (std::isinf(cone))
      {
        EXPECT_TRUE(std::isinf(fan)) << path;
        ++close;
        continue;
      }
      // The fan samples the sector: never nearer than the exact minimum, and almost always
      // within a millimetre of it (a ray may slip past a vertex poking into the sector).
      EXPECT_GE(fan, cone - 1e-9) << path;
      close += (fan - cone < 1e-3) ? 1 : 0;
    }
    EXPECT_GE(close, 190) << path;
  }
}

TEST(ConeCast, ZeroHalfAngleIsTheRay)
{
  const MapRayCaster map(loadPolyFile(test::bundledMaps().front()));
  const Pose2 sensor = Pose2(map.grid().bounds().min.x() + 0.5, map.grid().bounds().min.y() + 0.5, 0.3);
  EXPECT_EQ(coneRange(map, sensor, 0.0), map.range(sensor));
  EXPECT_EQ(coneRange(map, sensor, 0.0, 0.1), map.range(sensor, 0.1));
}

TEST(ConeCast, FacingAWallTheConeSeesThePerpendicularFoot)
{
  // A wall at x = 2 seen from the origin heading 0.4 rad: the ray hits at 2 / cos(0.4), a cone
  // of half-angle 0.5 contains the perpendicular foot at distance 2.
  const std::vector<Segment> wall{ { Vec2(2.0, -10.0), Vec2(2.0, 10.0) } };
  EXPECT_NEAR(coneRangeBruteForce(wall, Pose2(0, 0, 0.4), 0.5), 2.0, 1e-12);
  EXPECT_NEAR(coneRangeBruteForce(wall, Pose2(0, 0, 0.4), 0.1), 2.0 / std::cos(0.3), 1e-12);
  EXPECT_TRUE(std::isinf(coneRangeBruteForce(wall, Pose2(0, 0, kPi), 0.5)));
  EXPECT_TRUE(std::isinf(coneRangeBruteForce(wall, Pose2(0, 0, 0.0), 0.5, 1.9)));
}

MapRayCaster rectangleRoom(double x0, double y0, double x1, double y1)
{
  return MapRayCaster(PolygonMap::fromRings({ { Vec2(x0, y0), Vec2(x1, y0), Vec2(x1, y1), Vec2(x0, y1) } }));
}

TEST(ConeCast, HalfPlaneSeesTheSideWallsButNotBehind)
{
  // Room [-1, 3] x [-2, 2] from the origin: the half-plane facing +x contains the feet (0, +-2)
  // on its boundary line (distance 2), not the wall behind at distance 1.
  const MapRayCaster room = rectangleRoom(-1.0, -2.0, 3.0, 2.0);
  EXPECT_NEAR(coneRange(room, Pose2(0, 0, 0.0), kMaxConeHalfAngle), 2.0, 1e-9);
  EXPECT_NEAR(coneRange(room, Pose2(0, 0, kPi), kMaxConeHalfAngle), 1.0, 1e-9);
  EXPECT_NEAR(coneRange(room, Pose2(0, 0, 0.0), kMaxConeHalfAngle - 0.01), 2.0 / std::cos(0.01), 1e-9);
  // Turned a little towards the top wall, the half-plane holds its foot inside.
  EXPECT_NEAR(coneRange(room, Pose2(0, 0, 0.2), kMaxConeHalfAngle), 2.0, 1e-9);
  EXPECT_NEAR(coneRange(room, Pose2(0, 0, kPi / 2), kMaxConeHalfAngle), 1.0, 1e-9);
}

TEST(ConeCast, SensorOnAWallOrCornerReadsZeroLikeTheRay)
{
  const MapRayCaster room = rectangleRoom(-2.0, -2.0, 2.0, 2.0);
  for (const Pose2& sensor :
       { Pose2(0.0, -2.0, kPi / 2), Pose2(0.0, -2.0, 0.0), Pose2(-2.0, -2.0, kPi / 4), Pose2(2.0, 0.5, kPi) })
  {
    for (const double a : { 0.0, 0.01, 0.4, kMaxConeHalfAngle })
    {
      EXPECT_EQ(coneRange(room, sensor, a), 0.0) << sensor.x << " " << sensor.y << " a " << a;
      EXPECT_EQ(coneRangeBruteForce(room.grid().segments(), sensor, a), 0.0);
    }
  }
}

TEST(ConeCast, MaxRangeCutsAtTheNearestPoint)
{
  const MapRayCaster room = rectangleRoom(-1.0, -2.0, 3.0, 2.0);
  const Pose2 sensor(0.0, 0.0, 0.0);  // nearest in a 60 deg half-angle: (3, 3 tan 60) ... the wall x = 3
  EXPECT_NEAR(coneRange(room, sensor, 1.0), 2.0 / std::sin(1.0), 1e-9);
  const double nearest = coneRange(room, sensor, 1.0);
  EXPECT_EQ(coneRange(room, sensor, 1.0, nearest), nearest);
  EXPECT_TRUE(std::isinf(coneRange(room, sensor, 1.0, nearest - 1e-9)));
  EXPECT_TRUE(std::isinf(coneRangeBruteForce(room.grid().segments(), sensor, 1.0, nearest - 1e-9)));
  EXPECT_NEAR(coneRange(room, sensor, 1.0, 100.0), nearest, 0.0);
}

TEST(ConeCast, RejectsInvalidHalfAngles)
{
  const MapRayCaster room = rectangleRoom(-1.0, -1.0, 1.0, 1.0);
  for (const double a : { -0.1, kMaxConeHalfAngle + 1e-6, std::nan(""), kInf })
  {
    EXPECT_THROW(coneRange(room, Pose2(), a), std::invalid_argument) << a;
  }
}

/// Nearest point of a disc within a sector, sampled: the fan of ray entries.
double circleFan(const Pose2& sensor, double half_angle, const Vec2& centre, double radius, int rays)
{
  double best = kInf;
  for (int i = 0; i <= rays; ++i)
  {
    const double phi = sensor.theta - half_angle + 2.0 * half_angle * i / rays;
    best = std::min(best, rayCircleDistance(sensor.position(), test::unitDir(phi), centre, radius));
  }
  return best;
}

TEST(SectorCircleDistance, MatchesAFanOfRays)
{
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  std::uniform_real_distribution<double> ut(-kPi, kPi);
  std::uniform_real_distribution<double> ua(0.0, kMaxConeHalfAngle);
  std::uniform_real_distribution<double> ur(0.05, 1.0);
  int hits = 0;
  for (int trial = 0; trial < 3000; ++trial)
  {
    const Pose2 sensor(u(rng), u(rng), ut(rng));
    const double a = ua(rng);
    const Vec2 centre(u(rng), u(rng));
    const double radius = ur(rng);
    const double exact = sectorCircleDistance(Sector::around(sensor, a), centre, radius);
    const double fan = circleFan(sensor, a, centre, radius, 4000);
    if (std::isinf(fan))
    {
      // The fan can only miss a disc that the sector grazes between two rays.
      EXPECT_TRUE(std::isinf(exact) || exact > 0.0) << trial;
      continue;
    }
    ++hits;
    EXPECT_LE(exact, fan + 1e-12) << trial;
    // A ray off the nearest direction by at most half the step s = 2a / 4000 enters the disc
    // later by at most D^2 / (2 radius) (s / 2)^2, D the distance to the centre.
    const double half_step = a / 4000;
    const double d = (centre - sensor.position()).norm();
    EXPECT_NEAR(exact, fan, 1e-9 + d * d / (2.0 * radius) * half_step * half_step) << trial;
  }
  EXPECT_GT(hits, 500);
}

TEST(SectorCircleDistance, EdgeCases)
{
  const Sector ahead = Sector::around(Pose2(0, 0, 0), 0.3);
  EXPECT_EQ(sectorCircleDistance(ahead, Vec2(0.05, 0.0), 0.1), 0.0);           // apex inside
  EXPECT_NEAR(sectorCircleDistance(ahead, Vec2(2.0, 0.0), 0.5), 1.5, 1e-15);   // centre ahead
  EXPECT_TRUE(std::isinf(sectorCircleDistance(ahead, Vec2(-2.0, 0.0), 0.5)));  // behind
  EXPECT_TRUE(std::isinf(sectorCircleDistance(ahead, Vec2(0.0, 2.0), 0.5)));   // to the side
  // Centre outside the sector, the disc reaching into it: entered by the left bounding ray.
  const Vec2 centre(2.0, 2.0 * std::tan(0.3) + 0.3);
  const double expected = rayCircleDistance(Vec2::Zero(), test::unitDir(0.3), centre, 0.4);
  EXPECT_TRUE(std::isfinite(expected));
  EXPECT_EQ(sectorCircleDistance(ahead, centre, 0.4), expected);
  // A half-plane sees a disc beside the sensor.
  EXPECT_NEAR(sectorCircleDistance(Sector::around(Pose2(0, 0, 0), kMaxConeHalfAngle), Vec2(0.0, 2.0), 0.5), 1.5, 1e-12);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
