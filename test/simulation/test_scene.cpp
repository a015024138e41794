// Scene casts (static map plus disc and polygon obstacles) against a brute-force minimum over
// the map's edges and every obstacle, and Scene::isFree against independent containment tests.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/scene.h"

#include "scene_test_util.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::insideAnyObstacle;
using test::randomObstacles;

/// Counts of what the casts checked.
struct CastCounts
{
  int obstacle_hits = 0;
  int out_of_range = 0;
};

/// One scene cast against the brute-force minimum; false once a check has failed.
bool checkCast(const Scene& scene, const std::vector<Obstacle>& obstacles, const Pose2& sensor, double max_range,
               CastCounts* counts)
{
  const test::BruteHit expected = test::bruteSceneRay(scene.map(), obstacles, sensor.position(), sensor.heading());
  const SceneHit hit = scene.cast(sensor, max_range);
  if (expected.distance > max_range)
  {
    ++counts->out_of_range;
    EXPECT_EQ(hit.kind, SceneHit::Kind::None);
    return hit.kind == SceneHit::Kind::None;
  }
  EXPECT_NEAR(hit.distance, expected.distance, 1e-9);
  counts->obstacle_hits += expected.obstacle >= 0 ? 1 : 0;
  EXPECT_EQ(hit.kind, expected.obstacle >= 0 ? SceneHit::Kind::Obstacle : SceneHit::Kind::Map);
  EXPECT_EQ(hit.obstacle, expected.obstacle);
  if (std::isinf(max_range))
  {
    EXPECT_NEAR(hit.map_distance, expected.map_distance, 1e-9);
  }
  return !::testing::Test::HasFailure();
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
    CastCounts counts;
    for (int casts = 0; casts < 20000;)
    {
      const Vec2 p(ux(rng), uy(rng));
      if (!caster->isFree(p) || insideAnyObstacle(p, obstacles))
      {
        continue;
      }
      ++casts;
      const Pose2 sensor(p.x(), p.y(), angle(rng));
      const double max_range = casts % 3 == 0 ? 4.0 * unit(rng) : kInf;
      ASSERT_TRUE(checkCast(scene, obstacles, sensor, max_range, &counts)) << "cast " << casts;
    }
    EXPECT_GT(counts.obstacle_hits, 200);
    EXPECT_GT(counts.out_of_range, 100);
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
