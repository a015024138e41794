// Random polygons and generated buildings: always valid (checked independently of the
// library's validation), deterministic per seed, and the parameters are checked.
#include "fdml_localization/simulation/map_generators.h"
#include "fdml_localization/core/geometry/ray_caster.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
TEST(RandomPolygon, ValidStarShapedForManySeeds)
{
  for (int vertices : { 3, 4, 5, 10, 70, 200 })
  {
    for (double noise : { 0.0, 0.5, 0.95 })
    {
      for (std::uint64_t seed = 0; seed < 40; ++seed)
      {
        const PolygonMap map = randomPolygon(vertices, 1.5, noise, seed);
        const std::string what =
            std::to_string(vertices) + " vertices, noise " + std::to_string(noise) + ", seed " + std::to_string(seed);
        ASSERT_EQ(map.rings().size(), 1u) << what;
        const Ring& ring = map.outer();
        ASSERT_EQ(ring.size(), static_cast<std::size_t>(vertices)) << what;
        ASSERT_EQ(test::strictRingProblem(map.rings(), 0.0), "") << what;
        ASSERT_TRUE(validateRings(map.rings()).empty()) << what;
        ASSERT_GT(signedArea(ring), 0.0) << what;
        // Star-shaped about the origin: the origin is inside and the vertex angles increase.
        ASSERT_TRUE(map.containsBruteForce(Vec2::Zero())) << what;
        double turned = 0.0;
        for (std::size_t i = 0; i < ring.size(); ++i)
        {
          const Vec2& a = ring[i];
          const Vec2& b = ring[(i + 1) % ring.size()];
          const double step = std::atan2(a.x() * b.y() - a.y() * b.x(), a.dot(b));
          ASSERT_GT(step, 0.0) << what << " vertex " << i;
          turned += step;
          const double r = a.norm();
          ASSERT_GE(r, 1.5 * (1.0 - noise) - 1e-12) << what;
          ASSERT_LE(r, 1.5 * (1.0 + noise) + 1e-12) << what;
        }
        ASSERT_NEAR(turned, kTwoPi, 1e-9) << what;
      }
    }
  }
}

TEST(RandomPolygon, SameSeedSameMapAndThePaperScene)
{
  const PolygonMap a = randomPolygon(70, 1.0, 0.5, 9);
  const PolygonMap b = randomPolygon(70, 1.0, 0.5, 9);
  const PolygonMap c = randomPolygon(70, 1.0, 0.5, 10);
  EXPECT_EQ(a.hash(), b.hash());
  EXPECT_EQ(a.rings(), b.rings());
  EXPECT_NE(a.hash(), c.hash());
  // The paper's "random" scene: a 70-gon of mean radius 1, scaled by 2.
  const PolygonMap scene = a.scaled(2.0);
  EXPECT_EQ(scene.outer().size(), 70u);
  EXPECT_NEAR(scene.area(), 4.0 * a.area(), 1e-9);
  EXPECT_LE(scene.bounds().max.maxCoeff(), 3.0 + 1e-12);
  EXPECT_GE(scene.bounds().min.minCoeff(), -3.0 - 1e-12);
}

TEST(RandomPolygon, RejectsBadParameters)
{
  EXPECT_THROW(randomPolygon(2, 1.0, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(randomPolygon(10, 0.0, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(randomPolygon(10, -1.0, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(randomPolygon(10, NAN, 0.1, 1), std::invalid_argument);
  EXPECT_THROW(randomPolygon(10, 1.0, 1.0, 1), std::invalid_argument);
  EXPECT_THROW(randomPolygon(10, 1.0, -0.1, 1), std::invalid_argument);
  try
  {
    randomPolygon(10, 1.0, 1.5, 1);
    FAIL() << "no error";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("radius_noise"), std::string::npos) << e.what();
  }
}

namespace
{
struct Size
{
  double width, height;
};

void checkBuilding(const BuildingOptions& options)
{
  const std::string what =
      std::to_string(options.width) + " x " + std::to_string(options.height) + " seed " + std::to_string(options.seed);
  const PolygonMap map = generateBuilding(options);
  ASSERT_FALSE(map.empty()) << what;
  EXPECT_TRUE(validateRings(map.rings()).empty()) << what;
  // Holes keep at least a fraction of a wall thickness from each other and the outer ring.
  EXPECT_EQ(test::strictRingProblem(map.rings(), 0.1 * options.wall_thickness), "") << what;
  const Box2& b = map.bounds();
  EXPECT_GE(b.min.x(), 0.0) << what;
  EXPECT_GE(b.min.y(), 0.0) << what;
  EXPECT_LE(b.max.x(), options.width) << what;
  EXPECT_LE(b.max.y(), options.height) << what;
  EXPECT_GT(map.area(), 0.5 * options.width * options.height) << what;
  EXPECT_LT(map.area(), options.width * options.height) << what;
  // Closed: every ray from the free space hits a wall.
  const MapRayCaster caster(map);
  std::mt19937_64 rng(options.seed);
  std::uniform_real_distribution<double> ux(0.0, options.width), uy(0.0, options.height), a(-kPi, kPi);
  for (int i = 0; i < 500; ++i)
  {
    const Vec2 p(ux(rng), uy(rng));
    if (caster.isFree(p))
    {
      ASSERT_TRUE(std::isfinite(caster.range(Pose2(p.x(), p.y(), a(rng))))) << what;
    }
  }
}
}  // namespace

TEST(GenerateBuilding, ValidForSeveralSizesAndSeeds)
{
  for (const Size& size :
       { Size{ 8.0, 8.0 }, Size{ 20.0, 12.0 }, Size{ 35.0, 22.0 }, Size{ 60.0, 40.0 }, Size{ 100.0, 70.0 } })
  {
    for (std::uint64_t seed : { 1, 2, 3, 4 })
    {
      BuildingOptions options;
      options.width = size.width;
      options.height = size.height;
      options.seed = seed;
      checkBuilding(options);
    }
  }
}

TEST(GenerateBuilding, ValidForOtherProportions)
{
  BuildingOptions narrow;
  narrow.room_size = 3.0;
  narrow.corridor_width = 1.2;
  narrow.wall_thickness = 0.1;
  narrow.door_width = 0.8;
  narrow.pillar_probability = 1.0;
  narrow.seed = 7;
  checkBuilding(narrow);
  BuildingOptions thick;
  thick.wall_thickness = 0.5;
  thick.room_size = 4.0;
  thick.pillar_probability = 0.0;
  thick.seed = 8;
  checkBuilding(thick);
}

TEST(GenerateBuilding, HasRoomsHolesAndPillars)
{
  BuildingOptions options;
  options.pillar_probability = 1.0;
  const PolygonMap map = generateBuilding(options);
  // Enclosed wall blocks and one pillar per room: many holes, many edges.
  EXPECT_GE(map.holeCount(), 20u);
  EXPECT_GE(map.edges().size(), 300u);
  options.pillar_probability = 0.0;
  EXPECT_LT(generateBuilding(options).holeCount(), map.holeCount());
}

TEST(GenerateBuilding, SameSeedSameMap)
{
  BuildingOptions options;
  options.seed = 42;
  const PolygonMap a = generateBuilding(options);
  const PolygonMap b = generateBuilding(options);
  EXPECT_EQ(a.rings(), b.rings());
  options.seed = 43;
  EXPECT_NE(generateBuilding(options).hash(), a.hash());
}

TEST(GenerateBuilding, RejectsBadOptions)
{
  auto expect_invalid = [](const BuildingOptions& o, const std::string& parameter) {
    try
    {
      generateBuilding(o);
      ADD_FAILURE() << "no error for bad " << parameter;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find(parameter), std::string::npos) << e.what();
    }
  };
  BuildingOptions o;
  o.width = 3.0;
  expect_invalid(o, "width");
  o = BuildingOptions();
  o.height = NAN;
  expect_invalid(o, "height");
  o = BuildingOptions();
  o.wall_thickness = -0.1;
  expect_invalid(o, "wall_thickness");
  o = BuildingOptions();
  o.door_width = 0.0;
  expect_invalid(o, "door_width");
  o = BuildingOptions();
  o.room_size = 1.0;
  expect_invalid(o, "room_size");
  o = BuildingOptions();
  o.corridor_width = 0.1;
  expect_invalid(o, "corridor_width");
  o = BuildingOptions();
  o.pillar_probability = 1.5;
  expect_invalid(o, "pillar_probability");
}

}  // namespace core
}  // namespace fdml_localization
