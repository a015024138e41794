// LocalizerOptions::search_region: two identical rooms side by side, whose readings cannot tell
// apart; a region holding one room bounds the search to it, in both engines, keeps the truth
// even at the region's edge, and makes the engines' cells finer (they cover the region only).
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

namespace core = fdml_localization::core;

namespace
{
/// Rooms [0, 4.8] x [0, 4] and [5.2, 10] x [0, 4]: a wall between them with gaps at both ends.
std::shared_ptr<const core::MapRayCaster> twinRooms()
{
  const core::Ring outer = { { 0, 0 }, { 10, 0 }, { 10, 4 }, { 0, 4 } };
  const core::Ring wall = { { 4.8, 0.5 }, { 4.8, 3.5 }, { 5.2, 3.5 }, { 5.2, 0.5 } };
  return std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings({ outer, wall }));
}

std::shared_ptr<const core::MapRayCaster> rectangle(double x0, double y0, double x1, double y1)
{
  const core::Ring ring = { { x0, y0 }, { x1, y0 }, { x1, y1 }, { x0, y1 } };
  return std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings({ ring }));
}

const core::Pose2 kTruth(2.3, 2.0, 0.3);
const core::Pose2 kTwin(kTruth.x + 5.2, kTruth.y, kTruth.theta);  ///< the same place in the other room

/// Eight exact readings from the truth; none passes near the gaps of the dividing wall.
std::vector<core::Reading> readings(const core::MapRayCaster& map)
{
  std::vector<core::Reading> out;
  for (int i = 0; i < 8; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.0, 0.0, i * core::kPi / 4.0);
    r.range = map.range(core::compose(kTruth, r.offset));
    out.push_back(r);
  }
  return out;
}

bool near(const core::Pose2& a, const core::Pose2& b)
{
  return (a.position() - b.position()).norm() < 0.05 && std::abs(core::angleDiff(a.theta, b.theta)) < 0.035;
}

bool anyNear(const core::Result& result, const core::Pose2& pose)
{
  for (const core::Candidate& c : result.candidates)
  {
    if (near(c.pose, pose))
    {
      return true;
    }
  }
  return false;
}

core::LocalizerOptions options(core::Engine engine, std::shared_ptr<const core::MapRayCaster> region)
{
  core::LocalizerOptions o;
  o.engine = engine;
  o.resolution = 64;
  o.search_region = std::move(region);
  return o;
}

class SearchRegion : public ::testing::TestWithParam<core::Engine>
{};
}  // namespace

TEST_P(SearchRegion, BoundsTheSearchToTheRegionsRoom)
{
  const auto map = twinRooms();
  const std::vector<core::Reading> batch = readings(*map);
  core::Localizer everywhere(map, options(GetParam(), nullptr));
  const core::Result both = everywhere.localize(batch);
  ASSERT_TRUE(anyNear(both, kTruth));
  ASSERT_TRUE(anyNear(both, kTwin)) << "the rooms must be indistinguishable for this test";

  core::Localizer left(map, options(GetParam(), rectangle(0.0, 0.0, 4.8, 4.0)));
  const core::Result found = left.localize(batch);
  ASSERT_FALSE(found.candidates.empty());
  EXPECT_TRUE(near(found.candidates.front().pose, kTruth));
  for (const core::Candidate& c : found.candidates)
  {
    EXPECT_LE(c.pose.x, 4.8) << "a candidate outside the region";
    EXPECT_TRUE(core::inSearchRegion(left.options(), c.pose.position()));
  }

  core::Localizer right(map, options(GetParam(), rectangle(5.2, 0.0, 10.0, 4.0)));
  const core::Result other = right.localize(batch);
  ASSERT_FALSE(other.candidates.empty());
  EXPECT_TRUE(near(other.candidates.front().pose, kTwin));
  EXPECT_FALSE(anyNear(other, kTruth));
}

TEST_P(SearchRegion, KeepsTheTruthOneCentimetreInsideItsEdge)
{
  const auto map = twinRooms();
  // A region whose right edge passes 1 cm right of the truth, and one whose left edge passes
  // 1 cm left of it: boxes straddling the edge are kept.
  for (const auto& region : { rectangle(0.0, 0.0, kTruth.x + 0.01, 4.0), rectangle(kTruth.x - 0.01, 0.0, 4.8, 4.0) })
  {
    core::Localizer localizer(map, options(GetParam(), region));
    const core::Result found = localizer.localize(readings(*map));
    EXPECT_TRUE(anyNear(found, kTruth)) << "region " << region->map().bounds().min.transpose() << " to "
                                        << region->map().bounds().max.transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(Engines, SearchRegion, ::testing::Values(core::Engine::Voxel, core::Engine::Adaptive));

TEST(SearchRegionBounds, CellsCoverTheRegionOnly)
{
  const auto map = twinRooms();
  const auto region = rectangle(1.0, 1.0, 3.0, 2.0);
  core::Localizer localizer(map, options(core::Engine::Voxel, region));
  const auto& voxel = dynamic_cast<core::VoxelEngine&>(localizer.engine());
  EXPECT_NEAR(voxel.grid().cell, 2.0 / 64, 1e-12);  // the region's longer side, not the map's 10 m
  const core::Box2 searched = core::searchBounds(*map, localizer.options());
  EXPECT_EQ(searched.min, core::Vec2(1.0, 1.0));
  EXPECT_EQ(searched.max, core::Vec2(3.0, 2.0));
  // A region reaching past the map is cut to the map's bounding box.
  const core::LocalizerOptions wide = options(core::Engine::Voxel, rectangle(-5.0, -5.0, 3.0, 20.0));
  EXPECT_EQ(core::searchBounds(*map, wide).min, core::Vec2(0.0, 0.0));
  EXPECT_EQ(core::searchBounds(*map, wide).max, core::Vec2(3.0, 4.0));
}

TEST(SearchRegionBounds, ARegionOutsideTheMapIsRefused)
{
  const auto map = twinRooms();
  for (const core::Engine engine : { core::Engine::Voxel, core::Engine::Adaptive })
  {
    EXPECT_THROW(core::Localizer(map, options(engine, rectangle(20.0, 0.0, 30.0, 4.0))), std::invalid_argument);
  }
}
