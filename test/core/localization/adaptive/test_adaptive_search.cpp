// The adaptive engine's box search: the arc bounds and the box test are conservative, the
// occupancy grid never answers "no" wrongly, the search never loses the truth with exact
// readings, resuming at a lower k' equals a fresh search, the budgets cut the search, and the
// box consensus bound below a count proves no pose of the box reaches it.
#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/certificate.h"
#include "fdml_localization/simulation/map_generators.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <tuple>

namespace fdml_localization
{
namespace core
{
namespace
{
Pose2 anyFreePose(const MapRayCaster& map, std::mt19937_64& rng)
{
  const Box2& b = map.map().bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()), ut(-kPi, kPi);
  Pose2 q;
  do
  {
    q = Pose2(ux(rng), uy(rng), ut(rng));
  } while (!map.isFree(q.position()));
  return q;
}

/// k readings turning in place, exact (sigma 0) or with Gaussian noise.
std::vector<Reading> turnInPlace(const MapRayCaster& map, const Pose2& q, int k, double sigma, std::mt19937_64& rng)
{
  std::vector<Reading> readings = test::exactReadings(map, q, test::inPlaceOffsets(k));
  std::normal_distribution<double> noise(0.0, 1.0);
  for (Reading& r : readings)
  {
    r.range += sigma * noise(rng);
  }
  return readings;
}

/// A box of size @p sx x @p sy x @p st [m, m, rad] holding @p q at a random place in it.
PoseBox boxHolding(const Pose2& q, double sx, double sy, double st, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> frac(0.0, 1.0);
  PoseBox box;
  box.x0 = q.x - sx * frac(rng);
  box.x1 = box.x0 + sx;
  box.y0 = q.y - sy * frac(rng);
  box.y1 = box.y0 + sy;
  box.t0 = q.theta - st * frac(rng);
  box.t1 = box.t0 + st;
  return box;
}

bool keepsTruth(const AdaptiveSearchResult& result, const Pose2& q)
{
  return test::truthInLeaves(result.leaves, q, 0);
}

TEST(RotatedArcBounds, ContainsEverySampleAndIsTight)
{
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0), ut(-kPi, kPi), ul(0.0, kTwoPi);
  for (int trial = 0; trial < 1000; ++trial)
  {
    const Vec2 v(u(rng), u(rng));
    const double t0 = ut(rng);
    const double t1 = t0 + ul(rng);
    const Box2 box = rotatedArcBounds(v, t0, t1);
    Box2 sampled;
    for (int s = 0; s <= 2000; ++s)
    {
      const double t = t0 + (t1 - t0) * s / 2000.0;
      const Vec2 p(std::cos(t) * v.x() - std::sin(t) * v.y(), std::sin(t) * v.x() + std::cos(t) * v.y());
      ASSERT_LE(box.min.x(), p.x() + 1e-12);
      ASSERT_LE(box.min.y(), p.y() + 1e-12);
      ASSERT_GE(box.max.x(), p.x() - 1e-12);
      ASSERT_GE(box.max.y(), p.y() - 1e-12);
      sampled.extend(p);
    }
    // Tight: the dense samples reach the box up to the sampling step.
    const double slack = v.norm() * (t1 - t0) / 2000.0 + 1e-9;
    EXPECT_LE((box.min - sampled.min).cwiseAbs().maxCoeff(), slack);
    EXPECT_LE((box.max - sampled.max).cwiseAbs().maxCoeff(), slack);
  }
}

TEST(ReadingMayExplain, NeverRejectsABoxHoldingTheTruth)
{
  const auto map = test::loadMap("maps/office.poly");
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> size(0.001, 2.0), off(-0.3, 0.3);
  for (int trial = 0; trial < 20000; ++trial)
  {
    const Pose2 q = anyFreePose(*map, rng);
    Reading r;
    r.offset = Pose2(off(rng), off(rng), wrapAngle(8.0 * off(rng)));
    if (!map->isFree(compose(q, r.offset).position()))
    {
      continue;
    }
    r.range = map->range(compose(q, r.offset));
    const double sx = size(rng), sy = size(rng), st = 2.0 * size(rng);
    const PoseBox box = boxHolding(q, sx, sy, st, rng);
    ASSERT_TRUE(readingMayExplain(*map, r, box, 0.0)) << "trial " << trial;
  }
}

TEST(ReadingMayExplain, NoReturnBoxTestIsConservativeAndPrunes)
{
  // A no-return reading (max range m) agrees at q when nothing is nearer than m - tau: a box
  // holding such a pose is never rejected; a box every pose of which sees a wall well within
  // m is rejected often (the test must prune, not only pass).
  const auto map = test::loadMap("maps/office.poly");
  const double tau = 0.02;
  std::mt19937_64 rng(13);
  std::uniform_real_distribution<double> size(0.001, 0.5), off(-0.3, 0.3), reach(0.3, 4.0);
  int blocked_boxes = 0, rejected = 0;
  for (int trial = 0; trial < 20000; ++trial)
  {
    const Pose2 q = anyFreePose(*map, rng);
    Reading r;
    r.offset = Pose2(off(rng), off(rng), wrapAngle(8.0 * off(rng)));
    r.range = kInf;
    r.max_range = reach(rng);
    const Pose2 sensor = compose(q, r.offset);
    if (!map->isFree(sensor.position()))
    {
      continue;
    }
    const double sx = size(rng), sy = size(rng), st = 0.5 * size(rng);
    const PoseBox box = boxHolding(q, sx, sy, st, rng);
    const bool may = readingMayExplain(*map, r, box, tau);
    if (map->range(sensor) >= r.max_range - tau)
    {
      ASSERT_TRUE(may) << "trial " << trial;
    }
    else if (map->range(sensor) + sx + sy + 4.0 * st < 0.5 * r.max_range)
    {
      ++blocked_boxes;
      rejected += may ? 0 : 1;
    }
  }
  EXPECT_GT(blocked_boxes, 1000);
  EXPECT_GT(rejected, blocked_boxes / 4) << rejected << " of " << blocked_boxes;
}

TEST(AdaptiveSearch, BoxConsensusBoundBelowNeededProvesNoPoseReachesIt)
{
  // Readings from a pose near q: the poses of a box holding q explain some of them. Whenever the
  // bound says fewer than `needed`, q (inside the box) must explain fewer; and it does prune.
  const auto map = test::loadMap("maps/apartment.poly");
  const double tau = 0.03;
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> size(0.005, 0.4), jitter(-0.15, 0.15), heading(-kPi, kPi);
  int pruned = 0;
  for (int trial = 0; trial < 3000; ++trial)
  {
    const Pose2 q = anyFreePose(*map, rng);
    std::vector<Pose2> offsets;
    for (int i = 0; i < 6; ++i)
    {
      offsets.emplace_back(0.0, 0.0, heading(rng));
    }
    Pose2 source;
    do
    {
      source = Pose2(q.x + jitter(rng), q.y + jitter(rng), q.theta + 0.5 * jitter(rng));
    } while (!map->isFree(source.position()));
    const std::vector<Reading> readings = test::exactReadings(*map, source, offsets);
    const PoseBox box = boxHolding(q, size(rng), size(rng), 0.5 * size(rng), rng);
    const int at_q = consensusWithin(*map, q, readings, tau);
    for (int needed = 1; needed <= 6; ++needed)
    {
      if (boxConsensusBound(*map, readings, tau, box, needed) < needed)
      {
        ASSERT_LT(at_q, needed) << "trial " << trial << " needed " << needed;
        ++pruned;
      }
    }
  }
  EXPECT_GT(pruned, 3000);
}

TEST(BoxOccupancy, NoIsNeverWrong)
{
  BuildingOptions building;
  building.width = 30.0;
  building.height = 20.0;
  building.seed = 5;
  const MapRayCaster map(generateBuilding(building));
  for (const double cell : { 0.05, 0.37 })
  {
    const BoxOccupancy occupancy(map, cell);
    std::mt19937_64 rng(21);
    const Box2& b = map.map().bounds();
    std::uniform_real_distribution<double> ux(b.min.x() - 1.0, b.max.x() + 1.0), uy(b.min.y() - 1.0, b.max.y() + 1.0),
        size(0.0, 1.0), unit(0.0, 1.0);
    int edge_no = 0, free_no = 0;
    for (int trial = 0; trial < 20000; ++trial)
    {
      Box2 box;
      box.extend(Vec2(ux(rng), uy(rng)));
      box.extend(box.min + Vec2(size(rng) * size(rng), size(rng) * size(rng)));
      const bool edge = occupancy.mayTouchEdge(box);
      ASSERT_TRUE(edge || !map.grid().anySegmentInBox(box)) << "trial " << trial;
      edge_no += edge ? 0 : 1;
      if (!occupancy.mayBeFree(box))
      {
        ++free_no;
        for (int s = 0; s < 20; ++s)
        {
          const Vec2 p = box.min + Vec2(unit(rng) * box.size().x(), unit(rng) * box.size().y());
          ASSERT_FALSE(map.isFree(p)) << "trial " << trial;
        }
      }
    }
    // Both answers prune: the grid is not trivially "maybe".
    EXPECT_GT(edge_no, 2000);
    EXPECT_GT(free_no, 1000);
  }
}

/// Zero misses with exact readings over many random poses on several maps (static maps).
TEST(AdaptiveSearch, ExactReadingsNeverLoseTheTruth)
{
  BuildingOptions building;
  building.width = 30.0;
  building.height = 20.0;
  building.seed = 9;
  const std::vector<std::tuple<std::shared_ptr<const MapRayCaster>, double, int>> maps = {
    { test::lRoomMap(), 0.05, 1000 },
    { test::loadMap("maps/office.poly"), 0.05, 1000 },
    { test::loadMap("maps/warehouse.poly"), 0.1, 500 },
    { std::make_shared<const MapRayCaster>(generateBuilding(building)), 0.1, 500 },
  };
  int total = 0;
  for (const auto& entry : maps)
  {
    const MapRayCaster& map = *std::get<0>(entry);
    const BoxOccupancy occupancy(map, std::get<1>(entry));
    AdaptiveSearchOptions options;
    options.cell_xy = std::get<1>(entry);
    options.cell_theta = kTwoPi / 256.0;
    options.min_count = 8;
    options.range_tolerance = 0.0;
    options.threads = 1;
    std::mt19937_64 rng(13);
    int misses = 0;
    for (int trial = 0; trial < std::get<2>(entry); ++trial)
    {
      const Pose2 q = anyFreePose(map, rng);
      const AdaptiveSearchResult result = adaptiveSearch(map, occupancy, turnInPlace(map, q, 8, 0.0, rng), options);
      ASSERT_FALSE(result.truncated);
      misses += keepsTruth(result, q) ? 0 : 1;
      ++total;
    }
    EXPECT_EQ(misses, 0) << "map " << total / 1000;
  }
  EXPECT_EQ(total, 3000);
}

TEST(AdaptiveSearch, NoiseWithinToleranceRarelyLosesTheTruth)
{
  const auto map = test::loadMap("maps/office.poly");
  const BoxOccupancy occupancy(*map, 0.05);
  std::mt19937_64 rng(14);
  const double tau = 0.03;
  AdaptiveSearchOptions options;
  options.cell_xy = 0.05;
  options.cell_theta = kTwoPi / 256.0;
  options.min_count = 10;
  options.range_tolerance = tau;
  options.threads = 1;
  int misses = 0;
  const int trials = 1000;
  for (int trial = 0; trial < trials; ++trial)
  {
    const Pose2 q = anyFreePose(*map, rng);
    misses += keepsTruth(adaptiveSearch(*map, occupancy, turnInPlace(*map, q, 10, tau / 3.0, rng), options), q) ? 0 : 1;
  }
  EXPECT_LT(misses, trials * 0.005) << misses << " misses in " << trials;
}

/// Lowering k' step by step on one search gives the same leaves as a fresh search per k'.
TEST(AdaptiveSearch, ResumingAtLowerCountsEqualsFreshSearches)
{
  const auto map = test::loadMap("maps/office.poly");
  const BoxOccupancy occupancy(*map, 0.1);
  std::mt19937_64 rng(15);
  for (int trial = 0; trial < 5; ++trial)
  {
    const Pose2 q = anyFreePose(*map, rng);
    std::vector<Reading> readings = turnInPlace(*map, q, 10, 0.0, rng);
    readings[2].range *= 0.5;
    readings[7].range *= 0.3;
    AdaptiveSearchOptions options;
    options.cell_xy = 0.1;
    options.cell_theta = kTwoPi / 128.0;
    options.floor_count = 6;
    AdaptiveSearch resumed(*map, occupancy, readings, options);
    for (int k = 10; k >= 6; --k)
    {
      std::vector<std::tuple<std::int64_t, std::int64_t, std::int64_t, int>> a, b;
      for (const LeafBox& l : resumed.run(k).leaves)
      {
        a.emplace_back(l.ix, l.iy, l.it, l.count);
      }
      options.min_count = k;
      for (const LeafBox& l : adaptiveSearch(*map, occupancy, readings, options).leaves)
      {
        b.emplace_back(l.ix, l.iy, l.it, l.count);
      }
      std::sort(a.begin(), a.end());
      std::sort(b.begin(), b.end());
      ASSERT_EQ(a, b) << "trial " << trial << " k' " << k;
    }
    EXPECT_TRUE(test::truthInLeaves(resumed.result().leaves, q, 8));
  }
}

TEST(AdaptiveSearch, BoxBudgetCutsTheSearchAndSaysSo)
{
  const auto map = test::loadMap("maps/warehouse.poly");
  std::mt19937_64 rng(15);
  const Pose2 q = anyFreePose(*map, rng);
  AdaptiveSearchOptions options;
  options.cell_xy = 0.005;
  options.cell_theta = 0.001;
  options.min_count = 3;
  options.max_boxes = 5000;
  const AdaptiveSearchResult result = adaptiveSearch(*map, turnInPlace(*map, q, 10, 0.0, rng), options);
  EXPECT_TRUE(result.truncated);
  EXPECT_LE(result.boxes_tested, options.max_boxes);
  EXPECT_FALSE(result.leaves.empty());
  EXPECT_TRUE(keepsTruth(result, q));
}

TEST(AdaptiveSearch, ResumedSearchStaysWithinTheBoxBudget)
{
  const auto map = test::loadMap("maps/office.poly");
  const BoxOccupancy occupancy(*map, 0.1);
  std::mt19937_64 rng(19);
  const Pose2 q = anyFreePose(*map, rng);
  std::vector<Reading> readings = turnInPlace(*map, q, 10, 0.0, rng);
  readings[4].range *= 0.5;
  AdaptiveSearchOptions options;
  options.cell_xy = 0.1;
  options.cell_theta = kTwoPi / 128.0;
  options.floor_count = 3;
  const long first = AdaptiveSearch(*map, occupancy, readings, options).run(10).boxes_tested;
  options.max_boxes = first + 200;
  AdaptiveSearch search(*map, occupancy, readings, options);
  EXPECT_FALSE(search.run(10).truncated);
  const AdaptiveSearchResult& result = search.run(3);
  EXPECT_TRUE(result.truncated);
  EXPECT_LE(result.boxes_tested, options.max_boxes);
  EXPECT_EQ(search.run(3).boxes_tested, result.boxes_tested);  // a cut search stays cut
}

TEST(AdaptiveSearch, DeadlineCutsTheSearchAndSaysSo)
{
  const auto map = test::loadMap("maps/warehouse.poly");
  std::mt19937_64 rng(16);
  const Pose2 q = anyFreePose(*map, rng);
  AdaptiveSearchOptions options;
  options.cell_xy = 0.001;
  options.cell_theta = 0.0005;
  options.min_count = 3;
  options.deadline = 1e-9;  // expires after the first level
  const AdaptiveSearchResult result = adaptiveSearch(*map, turnInPlace(*map, q, 10, 0.0, rng), options);
  EXPECT_TRUE(result.truncated);
  EXPECT_EQ(result.boxes_tested, 1);
  EXPECT_TRUE(keepsTruth(result, q));
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
