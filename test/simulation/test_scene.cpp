// Scene casts (static map plus disc and polygon obstacles) against a brute-force minimum over
// the map's edges and every obstacle, and Scene::isFree against independent containment tests.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/scene.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Independent ray/disc distance (origin outside the disc): project the centre on the ray.
double discDistance(const Vec2& o, const Vec2& d, const Vec2& c, double r)
{
  const double s = (c - o).dot(d);
  const double h2 = (c - o).squaredNorm() - s * s;
  if (h2 > r * r)
  {
    return kInf;
  }
  const double t = s - std::sqrt(r * r - h2);
  return t >= 0.0 ? t : kInf;
}

double polygonDistance(const Vec2& o, const Vec2& d, const Ring& ring)
{
  double best = kInf;
  for (std::size_t i = 0; i < ring.size(); ++i)
  {
    best = std::min(best, raySegmentDistance(o, d, Segment{ ring[i], ring[(i + 1) % ring.size()] }));
  }
  return best;
}

std::vector<Obstacle> randomObstacles(const Box2& b, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Obstacle> obstacles;
  for (int i = 0; i < 20; ++i)
  {
    obstacles.push_back(Obstacle::disc(Vec2(ux(rng), uy(rng)), 0.05 + 0.5 * unit(rng)));
  }
  for (int i = 0; i < 8; ++i)
  {
    // Star-shaped (possibly non-convex) polygons of 3 to 7 vertices.
    const Vec2 c(ux(rng), uy(rng));
    const int n = 3 + i % 5;
    Ring ring;
    for (int k = 0; k < n; ++k)
    {
      const double a = kTwoPi * (k + 0.8 * unit(rng)) / n;
      ring.push_back(c + (0.2 + 0.6 * unit(rng)) * test::unitDir(a));
    }
    obstacles.push_back(Obstacle::polygon(ring));
  }
  return obstacles;
}

bool insideAnyObstacle(const Vec2& p, const std::vector<Obstacle>& obstacles)
{
  for (const Obstacle& o : obstacles)
  {
    const bool inside =
        o.shape == Obstacle::Shape::Disc ? (p - o.centre).norm() <= o.radius : pointInRing(p, o.vertices);
    if (inside)
    {
      return true;
    }
  }
  return false;
}
}  // namespace

TEST(Scene, CastEqualsBruteForceMinimum)
{
  for (const char* name : { "office.poly", "apartment.poly", "warehouse.poly" })
  {
    SCOPED_TRACE(name);
    auto caster = std::make_shared<const MapRayCaster>(loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/" + name));
    Scene scene(caster);
    std::mt19937_64 rng(61);
    const Box2& b = caster->map().bounds();
    const std::vector<Obstacle> obstacles = randomObstacles(b, rng);
    scene.setObstacles(obstacles);
    std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
    std::uniform_real_distribution<double> angle(-kPi, kPi), unit(0.0, 1.0);
    int casts = 0, obstacle_hits = 0, out_of_range = 0;
    while (casts < 20000)
    {
      const Vec2 p(ux(rng), uy(rng));
      if (!caster->isFree(p) || insideAnyObstacle(p, obstacles))
      {
        continue;
      }
      ++casts;
      const Pose2 sensor(p.x(), p.y(), angle(rng));
      const double max_range = casts % 3 == 0 ? 4.0 * unit(rng) : kInf;
      const Vec2 d = sensor.heading();
      const double map_distance = caster->grid().castBruteForce(p, d).distance;
      double expected = map_distance;
      int expected_obstacle = -1;
      for (std::size_t i = 0; i < obstacles.size(); ++i)
      {
        const Obstacle& o = obstacles[i];
        const double t = o.shape == Obstacle::Shape::Disc ? discDistance(p, d, o.centre, o.radius) :
                                                            polygonDistance(p, d, o.vertices);
        if (t < expected)
        {
          expected = t;
          expected_obstacle = static_cast<int>(i);
        }
      }
      const SceneHit hit = scene.cast(sensor, max_range);
      if (expected > max_range)
      {
        ++out_of_range;
        ASSERT_EQ(hit.kind, SceneHit::Kind::None) << "cast " << casts;
        continue;
      }
      ASSERT_NEAR(hit.distance, expected, 1e-9) << "cast " << casts;
      if (expected_obstacle >= 0)
      {
        ++obstacle_hits;
        ASSERT_EQ(hit.kind, SceneHit::Kind::Obstacle) << "cast " << casts;
        ASSERT_EQ(hit.obstacle, expected_obstacle) << "cast " << casts;
      }
      else
      {
        ASSERT_EQ(hit.kind, SceneHit::Kind::Map) << "cast " << casts;
      }
      if (std::isinf(max_range))
      {
        ASSERT_NEAR(hit.map_distance, map_distance, 1e-9) << "cast " << casts;
      }
    }
    EXPECT_GT(obstacle_hits, 200);
    EXPECT_GT(out_of_range, 100);
  }
}

TEST(Scene, IsFreeExcludesObstacles)
{
  auto caster = std::make_shared<const MapRayCaster>(loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/office.poly"));
  Scene scene(caster);
  std::mt19937_64 rng(71);
  const Box2& b = caster->map().bounds();
  const std::vector<Obstacle> obstacles = randomObstacles(b, rng);
  scene.setObstacles(obstacles);
  std::uniform_real_distribution<double> ux(b.min.x() - 1, b.max.x() + 1), uy(b.min.y() - 1, b.max.y() + 1);
  int blocked = 0;
  for (int i = 0; i < 20000; ++i)
  {
    const Vec2 p(ux(rng), uy(rng));
    const bool expected = caster->map().containsBruteForce(p) && !insideAnyObstacle(p, obstacles);
    blocked += (caster->map().containsBruteForce(p) && !expected) ? 1 : 0;
    ASSERT_EQ(scene.isFree(p), expected) << p.transpose();
  }
  EXPECT_GT(blocked, 50);
  EXPECT_THROW(Scene(nullptr), std::invalid_argument);
}

}  // namespace core
}  // namespace fdml_localization
