// The exact cone cast against an independent reference: the minimum over a dense fan of rays
// (brute force over every edge) can only be longer than the sector's nearest point, and comes
// within the fan's chord error of it.
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/map/map_io.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

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
    const Vec2 dir(std::cos(phi), std::sin(phi));
    best = std::min(best, grid.castBruteForce(sensor.position(), dir, max_range).distance);
  }
  return best;
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
    while (checked < 300)
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
      EXPECT_EQ(cone, coneRangeBruteForce(map.grid().segments(), sensor, a, max_range)) << path;
      const int rays = 2000;
      const double fan = fanMinimum(map.grid(), sensor, a, max_range, rays);
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
    EXPECT_GE(close, 290) << path;
  }
}

TEST(ConeCast, ZeroHalfAngleIsTheRay)
{
  const MapRayCaster map(loadPolyFile(test::bundledMaps().front()));
  const Pose2 sensor = Pose2(map.grid().bounds().min.x() + 0.5, map.grid().bounds().min.y() + 0.5, 0.3);
  EXPECT_EQ(coneRange(map, sensor, 0.0), map.range(sensor));
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

}  // namespace
}  // namespace core
}  // namespace fdml_localization
