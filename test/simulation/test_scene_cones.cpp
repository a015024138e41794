// Scene cone casts (the map's exact cone cast plus the nearest point of every disc and polygon
// obstacle inside the sector) against a brute-force fan of scene rays: the fan never sees
// nearer than the exact answer, comes within a millimetre of it, and names the same obstacle.
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
constexpr int kFanRays = 1500;

/// The nearest brute-force scene hit over a fan of rays spanning the sector.
test::BruteHit fanMinimum(const Scene& scene, const Pose2& sensor, double half_angle)
{
  test::BruteHit best;
  for (int i = 0; i <= kFanRays; ++i)
  {
    const double phi = sensor.theta - half_angle + 2.0 * half_angle * i / kFanRays;
    const test::BruteHit hit =
        test::bruteSceneRay(scene.map(), scene.obstacles(), sensor.position(), test::unitDir(phi));
    if (hit.distance < best.distance)
    {
      best = hit;
    }
  }
  return best;
}

struct ConeCounts
{
  int checked = 0;
  int close = 0;          ///< the fan within 1 mm of the exact answer
  int obstacle_hits = 0;  ///< the exact answer is an obstacle
  int label_matches = 0;  ///< among the close ones: the same obstacle (or the map) as the fan
  int out_of_range = 0;
};

void checkCone(const Scene& scene, const Pose2& sensor, double a, double max_range, ConeCounts* counts)
{
  const SceneHit hit = scene.castCone(sensor, a, max_range);
  const test::BruteHit fan = fanMinimum(scene, sensor, a);
  ++counts->checked;
  EXPECT_EQ(hit.map_distance, coneRange(scene.map(), sensor, a, max_range));
  if (hit.kind == SceneHit::Kind::None)
  {
    ++counts->out_of_range;
    EXPECT_GT(fan.distance, max_range);
    return;
  }
  EXPECT_LE(hit.distance, max_range);
  EXPECT_GE(fan.distance, hit.distance - 1e-9);
  counts->obstacle_hits += hit.kind == SceneHit::Kind::Obstacle ? 1 : 0;
  if (fan.distance - hit.distance < 1e-3)
  {
    ++counts->close;
    counts->label_matches += fan.obstacle == hit.obstacle ? 1 : 0;
  }
  EXPECT_EQ(hit.kind == SceneHit::Kind::Obstacle, hit.obstacle >= 0);
}

TEST(SceneCones, CastConeMatchesAFanOfSceneRays)
{
  for (const char* name : { "office.poly", "apartment.poly" })
  {
    SCOPED_TRACE(name);
    auto caster = std::make_shared<const MapRayCaster>(loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/" + name));
    Scene scene(caster);
    std::mt19937_64 rng(83);
    const Box2& b = caster->map().bounds();
    scene.setObstacles(test::randomObstacles(b, rng));
    std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
    std::uniform_real_distribution<double> angle(-kPi, kPi), ua(0.0, 0.3), unit(0.0, 1.0);
    ConeCounts counts;
    while (counts.checked < 300)
    {
      const Pose2 sensor(ux(rng), uy(rng), angle(rng));
      if (!scene.isFree(sensor.position()))
      {
        continue;
      }
      const double a = counts.checked % 10 == 0 ? kMaxConeHalfAngle : ua(rng);
      const double max_range = counts.checked % 3 == 0 ? 4.0 * unit(rng) : kInf;
      checkCone(scene, sensor, a, max_range, &counts);
    }
    const int seen = counts.checked - counts.out_of_range;
    EXPECT_GE(counts.close, seen - seen / 30);
    EXPECT_GE(counts.label_matches, counts.close - counts.close / 30);
    EXPECT_GT(counts.obstacle_hits, 30);
    EXPECT_GT(counts.out_of_range, 5);
  }
}

TEST(SceneCones, ZeroHalfAngleIsTheRayCast)
{
  auto caster = std::make_shared<const MapRayCaster>(loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/"
                                                                                                 "apartment.poly"));
  Scene scene(caster);
  std::mt19937_64 rng(89);
  const Box2& b = caster->map().bounds();
  scene.setObstacles(test::randomObstacles(b, rng));
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()), angle(-kPi, kPi);
  for (int i = 0; i < 2000; ++i)
  {
    const Pose2 sensor(ux(rng), uy(rng), angle(rng));
    const SceneHit ray = scene.cast(sensor, 5.0);
    const SceneHit cone = scene.castCone(sensor, 0.0, 5.0);
    ASSERT_EQ(cone.distance, ray.distance);
    ASSERT_EQ(cone.kind, ray.kind);
    ASSERT_EQ(cone.obstacle, ray.obstacle);
    ASSERT_EQ(cone.map_distance, ray.map_distance);
  }
}

TEST(SceneCones, ADiscBesideTheAxisShortensTheCone)
{
  // A 27 deg cone along +x in a 10 m square room; a disc off the axis (the ray misses it) is
  // the nearest point inside the cone.
  auto caster = std::make_shared<const MapRayCaster>(
      PolygonMap::fromRings({ { Vec2(-5, -5), Vec2(5, -5), Vec2(5, 5), Vec2(-5, 5) } }));
  Scene scene(caster);
  scene.setObstacles({ Obstacle::disc(Vec2(2.0, 0.4), 0.2) });
  const Pose2 sensor(0.0, 0.0, 0.0);
  EXPECT_EQ(scene.cast(sensor).kind, SceneHit::Kind::Map);
  const SceneHit hit = scene.castCone(sensor, 0.5 * 27.0 * kPi / 180.0);
  EXPECT_EQ(hit.kind, SceneHit::Kind::Obstacle);
  EXPECT_EQ(hit.obstacle, 0);
  EXPECT_NEAR(hit.distance, std::hypot(2.0, 0.4) - 0.2, 1e-12);
  EXPECT_NEAR(hit.map_distance, 5.0, 1e-12);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
