// Tests of the local solve: the box search restricted to a region (AdaptiveSearchOptions::region)
// never loses a pose of the box that explains the readings, and a box without one holds no fix.
#include "fdml_localization/core/map/map_io.h"

#include "localizer_test_utils.h"
#include "fdml_localization/core/tracking/local_solve.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

namespace core = fdml_localization::core;

namespace
{

/// k readings from @p truth: four sensors at several headings of a turn.
std::vector<core::Reading> readingsAt(const core::MapRayCaster& map, const core::Pose2& truth, int k)
{
  std::vector<core::Reading> readings;
  for (int i = 0; i < k; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.15 * std::cos(i * 0.5 * M_PI), 0.15 * std::sin(i * 0.5 * M_PI), i * 0.5 * M_PI + 0.1 * i);
    r.max_range = 8.0;
    r.range = map.range(core::compose(truth, r.offset), r.max_range);
    readings.push_back(r);
  }
  return readings;
}

core::PoseBox around(const core::Pose2& p, double xy, double theta)
{
  return core::PoseBox{ p.x - xy, p.x + xy, p.y - xy, p.y + xy, p.theta - theta, p.theta + theta };
}

/// A 20 x 2 m corridor with a door niche (0.4 m wide, 0.5 m deep) every 2 m, on both walls
/// facing each other: a niche pins the position along the corridor, but every niche looks alike.
std::shared_ptr<const core::MapRayCaster> corridorWithDoors()
{
  std::vector<core::Vec2> ring{ core::Vec2(0.0, 0.0) };
  for (int door = 1; door <= 9; ++door)
  {
    const double x = 2.0 * door + 1.0;
    ring.insert(ring.end(), { core::Vec2(x - 0.2, 0.0), core::Vec2(x - 0.2, -0.5), core::Vec2(x + 0.2, -0.5),
                              core::Vec2(x + 0.2, 0.0) });
  }
  ring.insert(ring.end(), { core::Vec2(20.0, 0.0), core::Vec2(20.0, 2.0) });
  for (int door = 9; door >= 1; --door)
  {
    const double x = 2.0 * door + 1.0;
    ring.insert(ring.end(), { core::Vec2(x + 0.2, 2.0), core::Vec2(x + 0.2, 2.5), core::Vec2(x - 0.2, 2.5),
                              core::Vec2(x - 0.2, 2.0) });
  }
  ring.push_back(core::Vec2(0.0, 2.0));
  return std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings({ ring }, "doors"));
}

/// From (x, 1, 0): six north and six south rays, 10 cm apart along the corridor, 3 m max range
/// (the corridor's ends are out of reach).
std::vector<core::Reading> doorReadings(const core::MapRayCaster& map, double x)
{
  std::vector<core::Reading> readings;
  for (int i = 0; i < 12; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.1 * (i % 6), 0.0, i < 6 ? core::kPi / 2 : -core::kPi / 2);
    r.max_range = 3.0;
    r.range = map.range(core::compose(core::Pose2(x, 1.0, 0.0), r.offset), r.max_range);
    readings.push_back(r);
  }
  return readings;
}
}  // namespace

TEST(LocalSolve, FindsTheTruthInEveryBoxHoldingIt)
{
  const auto map = core::test::loadMap("maps/apartment.poly");
  const core::BoxOccupancy occupancy(*map, 0.05);
  core::LocalSolveSettings settings;
  settings.min_consensus = 8;
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> off(-0.2, 0.2), turn(-0.1, 0.1);
  const core::Pose2 poses[] = { { 2.0, 2.0, 0.3 }, { 9.0, 3.0, -2.0 }, { 5.0, 5.7, 3.1 }, { 9.5, 7.0, 1.0 } };
  for (const core::Pose2& truth : poses)
  {
    const auto readings = readingsAt(*map, truth, 10);
    // A box around a prediction off by up to 0.2 m and 0.1 rad, holding the truth.
    const core::Pose2 predicted(truth.x + off(rng), truth.y + off(rng), truth.theta + turn(rng));
    const core::LocalSolveOutcome found =
        core::localSolve(*map, occupancy, readings, around(predicted, 0.3, 0.2), settings);
    ASSERT_FALSE(found.fixes.empty()) << "truth " << truth.x << ", " << truth.y;
    EXPECT_LT((found.fixes[0].pose.position() - truth.position()).norm(), 0.01);
    EXPECT_LT(std::abs(core::angleDiff(found.fixes[0].pose.theta, truth.theta)), 0.01);
    EXPECT_EQ(found.best_possible, 10);
    // A box 1 m away holds no pose explaining them.
    const core::Pose2 away(truth.x + 1.0, truth.y, truth.theta);
    const core::LocalSolveOutcome none = core::localSolve(*map, occupancy, readings, around(away, 0.3, 0.2), settings);
    EXPECT_TRUE(none.fixes.empty());
    EXPECT_LT(none.best_possible, 10);
  }
}

TEST(LocalSolve, RegionSearchKeepsEveryLeafTheWholeSearchKeeps)
{
  const auto map = core::test::loadMap("maps/apartment.poly");
  const core::BoxOccupancy occupancy(*map, 0.1);
  const core::Pose2 truth(3.0, 2.5, 0.7);
  const auto readings = readingsAt(*map, truth, 8);
  core::AdaptiveSearchOptions whole;
  whole.cell_xy = 0.1;
  whole.cell_theta = 0.05;
  whole.min_count = 7;
  whole.threads = 1;
  core::AdaptiveSearchOptions local = whole;
  local.region = around(truth, 0.5, 0.3);
  const auto all = core::adaptiveSearch(*map, occupancy, readings, whole);
  const auto inside = core::adaptiveSearch(*map, occupancy, readings, local);
  ASSERT_FALSE(inside.leaves.empty());
  // Every leaf of the whole search whose centre lies well inside the region is covered by a
  // leaf of the region's search (conservative: no false negative inside the box).
  for (const core::LeafBox& leaf : all.leaves)
  {
    const core::Pose2 c = leaf.box.centre();
    if (!core::insideBox(c, *local.region, -0.1, -0.05))
    {
      continue;
    }
    bool covered = false;
    for (const core::LeafBox& l : inside.leaves)
    {
      covered = covered || core::insideBox(c, l.box, 0.1, 0.05);
    }
    EXPECT_TRUE(covered) << c.x << ", " << c.y << ", " << c.theta;
  }
}

TEST(LocalSolve, AFixStaysAtThePriorAlongACorridor)
{
  // A 40 x 2 m corridor: in its middle the 8 m sensors see only the side walls, so the readings
  // leave the position along it free and fix the heading only to second order (0.5 mm of range
  // for 0.03 rad, under the 1 cm noise). The fix takes the readings' position across it and
  // keeps the prediction (the prior) for the rest; without the prior the polish wanders along
  // such directions (out of the box, in the building's corridors) or takes the noise's heading.
  const auto map = std::make_shared<const core::MapRayCaster>(
      core::PolygonMap::fromRings({ { { 0, 0 }, { 40, 0 }, { 40, 2 }, { 0, 2 } } }));
  const core::BoxOccupancy occupancy(*map, 0.05);
  const core::Pose2 truth(20.0, 1.0, 0.0);
  std::vector<core::Reading> readings;
  for (int i = 0; i < 10; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.01 * i + 0.15 * std::cos(i * 0.5 * M_PI), 0.15 * std::sin(i * 0.5 * M_PI), i * 0.5 * M_PI);
    r.max_range = 8.0;
    r.range = map->range(core::compose(truth, r.offset), r.max_range);
    readings.push_back(r);
  }
  const core::Pose2 predicted(20.08, 1.04, 0.03);
  core::LocalSolveSettings settings;
  settings.min_consensus = 8;
  settings.prior.mean = predicted;
  settings.prior.information = Eigen::Vector3d(1 / 0.0025, 1 / 0.0025, 1 / 0.0004).asDiagonal();
  const core::LocalSolveOutcome found =
      core::localSolve(*map, occupancy, readings, around(predicted, 0.15, 0.06), settings);
  ASSERT_FALSE(found.fixes.empty());
  const core::Pose2& fix = found.fixes[0].pose;
  EXPECT_LT(std::abs(fix.x - predicted.x), 0.01) << fix.x;
  EXPECT_LT(std::abs(fix.y - truth.y), 0.005) << fix.y;
  EXPECT_LT(std::abs(core::angleDiff(fix.theta, predicted.theta)), 0.01) << fix.theta;
  // The fix says the corridor's axis is undetermined (the tracker then keeps its prediction).
  EXPECT_GT(found.fixes[0].covariance(0, 0), 1.0);
}

TEST(LocalSolve, OnlyPlaceInRegionSeesTheAlikeDoors)
{
  // Readings taken at x = 10.45 by the niches at 11 are explained one door further on (12.45)
  // too: within 1 m of 12.45 that is the only place; over 9 m the niches at 11, 15 and 17 align
  // the same way.
  const auto map = corridorWithDoors();
  const std::vector<core::Reading> readings = doorReadings(*map, 10.45);
  ASSERT_NEAR(readings[5].range, 1.5, 1e-9) << "the last north ray looks into the niche";
  ASSERT_NEAR(readings[0].range, 1.0, 1e-9);
  const core::Pose2 place(12.45, 1.0, 0.0);
  core::LocalSolveSettings settings;
  settings.range_tolerance = 0.02;
  const int all = static_cast<int>(readings.size());
  const core::BoxOccupancy occupancy(*map, settings.cell_xy);
  EXPECT_TRUE(
      core::onlyPlaceInRegion(*map, occupancy, readings, around(place, 1.0, 0.1), place, all, 0.1, 0.05, settings));
  const core::PoseBox corridor{ 3.5, 21.5, 0.5, 1.5, -0.1, 0.1 };
  EXPECT_FALSE(core::onlyPlaceInRegion(*map, occupancy, readings, corridor, place, all, 0.1, 0.05, settings));
  // Where no niche is in reach, the corridor looks alike everywhere, also within 1 m.
  const std::vector<core::Reading> plain = doorReadings(*map, 9.4);
  EXPECT_FALSE(core::onlyPlaceInRegion(*map, occupancy, plain, around(core::Pose2(9.4, 1.0, 0.0), 1.0, 0.1),
                                       core::Pose2(9.4, 1.0, 0.0), all, 0.1, 0.05, settings));
}
