// Furnished rooms: valid with the clearance kept (checked independently of the library's
// validation), the rotation a true rotation, deterministic per seed, and the options checked.
#include "fdml_localization/simulation/furnished_room.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace core
{
namespace
{
std::string describe(const FurnishedRoomOptions& o)
{
  return std::string(o.round ? "round" : "rectangular") + " seed " + std::to_string(o.seed) + " rotation " +
         std::to_string(o.rotation);
}

/// The most distant vertex from the origin [m].
double farthestVertex(const PolygonMap& map)
{
  double r = 0.0;
  for (const Ring& ring : map.rings())
  {
    for (const Vec2& v : ring)
    {
      r = std::max(r, v.norm());
    }
  }
  return r;
}
}  // namespace

TEST(FurnishedRoom, ValidWithTheClearanceKeptForShapesSeedsAndAngles)
{
  for (bool round : { false, true })
  {
    for (std::uint64_t seed : { 1, 2, 3, 4 })
    {
      for (double rotation : { 0.0, 0.3, 2.0 })
      {
        FurnishedRoomOptions o;
        o.round = round;
        o.width = round ? 10.0 : 8.0;
        o.seed = seed;
        o.rotation = rotation;
        const PolygonMap map = furnishedRoom(o);
        EXPECT_TRUE(validateRings(map.rings()).empty()) << describe(o);
        // Discs around the pieces keep the clearance, so their polygons keep at least as much.
        EXPECT_EQ(test::strictRingProblem(map.rings(), 0.99 * o.clearance), "") << describe(o);
        EXPECT_EQ(map.holeCount(), static_cast<std::size_t>(o.pieces)) << describe(o);  // 20 fit easily
        const double outer = round ? 0.5 * o.wall_edges * 25.0 * std::sin(kTwoPi / o.wall_edges) : 8.0 * 6.0;
        EXPECT_LT(map.area(), outer) << describe(o);
        EXPECT_GT(map.area(), outer - o.pieces * o.max_size * o.max_size) << describe(o);
        EXPECT_LE(farthestVertex(map), round ? 5.0 + 1e-9 : std::hypot(4.0, 3.0) + 1e-9) << describe(o);
      }
    }
  }
}

TEST(FurnishedRoom, TheRotationTurnsTheSameRoom)
{
  FurnishedRoomOptions o;
  o.seed = 9;
  const PolygonMap upright = furnishedRoom(o);
  o.rotation = 0.7;
  const PolygonMap turned = furnishedRoom(o);
  ASSERT_EQ(upright.holeCount(), turned.holeCount());
  // Loading may start a ring elsewhere or reverse it: compare each ring's vertex set.
  for (std::size_t r = 0; r < upright.rings().size(); ++r)
  {
    for (const Vec2& v : upright.rings()[r])
    {
      const Vec2 w(std::cos(0.7) * v.x() - std::sin(0.7) * v.y(), std::sin(0.7) * v.x() + std::cos(0.7) * v.y());
      double nearest = kInf;
      for (const Vec2& u : turned.rings()[r])
      {
        nearest = std::min(nearest, (u - w).norm());
      }
      EXPECT_LT(nearest, 1e-9) << "ring " << r;
    }
  }
  EXPECT_NEAR(turned.area(), upright.area(), 1e-9);
}

TEST(FurnishedRoom, RoundHallWallIsARegularPolygon)
{
  FurnishedRoomOptions o;
  o.round = true;
  o.width = 10.0;
  o.wall_edges = 90;
  const PolygonMap map = furnishedRoom(o);
  ASSERT_EQ(map.outer().size(), 90u);
  for (const Vec2& v : map.outer())
  {
    EXPECT_NEAR(v.norm(), 5.0, 1e-9);
  }
}

TEST(FurnishedRoom, AFullRoomPlacesWhatFitsAndStaysValid)
{
  FurnishedRoomOptions o;
  o.width = 2.0;
  o.height = 1.5;
  o.max_size = 0.3;
  o.pieces = 1000;
  const PolygonMap map = furnishedRoom(o);
  EXPECT_GE(map.holeCount(), 1u);
  EXPECT_LT(map.holeCount(), 20u);  // discs of >= 5 cm radius 25 cm apart in 1.5 x 1 m
  EXPECT_EQ(test::strictRingProblem(map.rings(), 0.99 * o.clearance), "");
}

TEST(FurnishedRoom, SameSeedSameMap)
{
  FurnishedRoomOptions o;
  o.seed = 42;
  EXPECT_EQ(furnishedRoom(o).rings(), furnishedRoom(o).rings());
  const std::uint64_t first = furnishedRoom(o).hash();
  o.seed = 43;
  EXPECT_NE(furnishedRoom(o).hash(), first);
}

TEST(FurnishedRoom, RejectsBadOptionsNamingThem)
{
  const auto expect_invalid = [](const FurnishedRoomOptions& o, const std::string& option) {
    try
    {
      furnishedRoom(o);
      ADD_FAILURE() << "no error for bad " << option;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_EQ(std::string(e.what()).rfind(option + " = ", 0), 0u) << e.what();
    }
  };
  const auto with = [](auto change) {
    FurnishedRoomOptions o;
    change(o);
    return o;
  };
  expect_invalid(with([](FurnishedRoomOptions& o) { o.width = 0.5; }), "width");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.height = NAN; }), "height");
  expect_invalid(with([](FurnishedRoomOptions& o) {
                   o.round = true;
                   o.wall_edges = 7;
                 }),
                 "wall_edges");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.pieces = -1; }), "pieces");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.pieces = 1001; }), "pieces");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.min_size = 0.0; }), "min_size");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.max_size = 0.05; }), "max_size");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.max_size = 2.0; }), "max_size");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.clearance = INFINITY; }), "clearance");
  expect_invalid(with([](FurnishedRoomOptions& o) { o.rotation = NAN; }), "rotation");
  // A round hall's height is not used: any value is accepted.
  EXPECT_NO_THROW(furnishedRoom(with([](FurnishedRoomOptions& o) {
    o.round = true;
    o.height = NAN;
  })));
}

}  // namespace core
}  // namespace fdml_localization
