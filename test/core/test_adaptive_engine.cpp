// The adaptive engine: its box test is conservative, its search never loses the truth with
// exact readings, it respects its budgets, and it localizes in a building-sized map.
#include "fdml_localization/core/adaptive_engine.h"
#include "fdml_localization/core/localizer.h"
#include "fdml_localization/core/map_generators.h"
#include "fdml_localization/core/map_io.h"

#include <gtest/gtest.h>

#include <random>

namespace core = fdml_localization::core;

namespace
{
std::shared_ptr<const core::MapRayCaster> loadMap(const std::string& name)
{
  return std::make_shared<const core::MapRayCaster>(core::loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/" + name));
}

core::Pose2 randomFreePose(const core::MapRayCaster& map, std::mt19937_64& rng)
{
  const core::Box2& b = map.map().bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()),
      ut(-core::kPi, core::kPi);
  core::Pose2 q;
  do
  {
    q = core::Pose2(ux(rng), uy(rng), ut(rng));
  } while (!map.isFree(q.position()));
  return q;
}

/// k readings turning in place, exact (noise 0) or with Gaussian noise.
std::vector<core::Reading> turnInPlace(const core::MapRayCaster& map, const core::Pose2& q, int k, double sigma,
                                       std::mt19937_64& rng)
{
  std::normal_distribution<double> noise(0.0, sigma > 0.0 ? sigma : 1.0);
  std::vector<core::Reading> readings;
  for (int i = 0; i < k; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.0, 0.0, i * core::kTwoPi / k);
    r.range = map.range(core::compose(q, r.offset)) + (sigma > 0.0 ? noise(rng) : 0.0);
    readings.push_back(r);
  }
  return readings;
}

bool leafHolds(const core::LeafBox& leaf, const core::Pose2& q)
{
  return q.x >= leaf.box.x0 && q.x <= leaf.box.x1 && q.y >= leaf.box.y0 && q.y <= leaf.box.y1 &&
         q.theta >= leaf.box.t0 && q.theta <= leaf.box.t1;
}

bool searchKeepsTruth(const core::AdaptiveSearchResult& result, const core::Pose2& q)
{
  for (const core::LeafBox& leaf : result.leaves)
  {
    if (leafHolds(leaf, q))
    {
      return true;
    }
  }
  return false;
}
}  // namespace

TEST(RotatedArcBounds, ContainsEverySampleAndIsTight)
{
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u(-3.0, 3.0), ut(-core::kPi, core::kPi), ul(0.0, core::kTwoPi);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const core::Vec2 v(u(rng), u(rng));
    const double t0 = ut(rng);
    const double t1 = t0 + ul(rng);
    const core::Box2 box = core::rotatedArcBounds(v, t0, t1);
    core::Box2 sampled;
    for (int s = 0; s <= 2000; ++s)
    {
      const double t = t0 + (t1 - t0) * s / 2000.0;
      const core::Vec2 p(std::cos(t) * v.x() - std::sin(t) * v.y(), std::sin(t) * v.x() + std::cos(t) * v.y());
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
  const auto map = loadMap("office.poly");
  std::mt19937_64 rng(12);
  std::uniform_real_distribution<double> size(0.001, 2.0), frac(0.0, 1.0), off(-0.3, 0.3);
  for (int trial = 0; trial < 20000; ++trial)
  {
    const core::Pose2 q = randomFreePose(*map, rng);
    core::Reading r;
    r.offset = core::Pose2(off(rng), off(rng), core::wrapAngle(8.0 * off(rng)));
    if (!map->isFree(core::compose(q, r.offset).position()))
    {
      continue;
    }
    r.range = map->range(core::compose(q, r.offset));
    const double sx = size(rng), sy = size(rng), st = 2.0 * size(rng);
    core::PoseBox box;
    box.x0 = q.x - sx * frac(rng);
    box.x1 = box.x0 + sx;
    box.y0 = q.y - sy * frac(rng);
    box.y1 = box.y0 + sy;
    box.t0 = q.theta - st * frac(rng);
    box.t1 = box.t0 + st;
    ASSERT_TRUE(core::readingMayExplain(*map, r, box, 0.0)) << "trial " << trial;
  }
}

TEST(AdaptiveSearch, ExactReadingsNeverLoseTheTruth)
{
  for (const std::string name : { "l_room.poly", "office.poly", "warehouse.poly" })
  {
    const auto map = loadMap(name);
    std::mt19937_64 rng(13);
    core::AdaptiveSearchOptions options;
    options.cell_xy = std::max(map->map().bounds().size().x(), map->map().bounds().size().y()) / 128.0;
    options.cell_theta = core::kTwoPi / 128.0;
    options.min_count = 8;
    options.range_tolerance = 0.0;
    int misses = 0;
    for (int trial = 0; trial < 700; ++trial)
    {
      const core::Pose2 q = randomFreePose(*map, rng);
      const std::vector<core::Reading> readings = turnInPlace(*map, q, 8, 0.0, rng);
      const core::AdaptiveSearchResult result = core::adaptiveSearch(*map, readings, options);
      ASSERT_FALSE(result.truncated);
      misses += searchKeepsTruth(result, q) ? 0 : 1;
    }
    EXPECT_EQ(misses, 0) << name;
  }
}

TEST(AdaptiveSearch, NoiseWithinToleranceRarelyLosesTheTruth)
{
  const auto map = loadMap("office.poly");
  std::mt19937_64 rng(14);
  const double tau = 0.03;
  core::AdaptiveSearchOptions options;
  options.cell_xy = 0.1;
  options.cell_theta = core::kTwoPi / 128.0;
  options.min_count = 10;
  options.range_tolerance = tau;
  int misses = 0;
  const int trials = 1000;
  for (int trial = 0; trial < trials; ++trial)
  {
    const core::Pose2 q = randomFreePose(*map, rng);
    const std::vector<core::Reading> readings = turnInPlace(*map, q, 10, tau / 3.0, rng);
    misses += searchKeepsTruth(core::adaptiveSearch(*map, readings, options), q) ? 0 : 1;
  }
  EXPECT_LT(misses, trials * 0.005) << misses << " misses in " << trials;
}

TEST(AdaptiveSearch, BoxBudgetCutsTheSearchAndSaysSo)
{
  const auto map = loadMap("warehouse.poly");
  std::mt19937_64 rng(15);
  const core::Pose2 q = randomFreePose(*map, rng);
  core::AdaptiveSearchOptions options;
  options.cell_xy = 0.005;
  options.cell_theta = 0.001;
  options.min_count = 3;
  options.max_boxes = 5000;
  const core::AdaptiveSearchResult result = core::adaptiveSearch(*map, turnInPlace(*map, q, 10, 0.0, rng), options);
  EXPECT_TRUE(result.truncated);
  EXPECT_LE(result.boxes_tested, options.max_boxes);
  EXPECT_FALSE(result.leaves.empty());
  EXPECT_TRUE(searchKeepsTruth(result, q));
}

TEST(AdaptiveEngine, FindsTheTruthAndTheOutliersInTheOffice)
{
  const auto map = loadMap("office.poly");
  core::LocalizerOptions options;
  options.engine = core::Engine::Adaptive;
  options.resolution = 200;
  core::Localizer localizer(map, options);
  std::mt19937_64 rng(16);
  int found = 0, flagged = 0;
  const int trials = 40;
  for (int trial = 0; trial < trials; ++trial)
  {
    const core::Pose2 q = randomFreePose(*map, rng);
    std::vector<core::Reading> readings = turnInPlace(*map, q, 10, 0.0, rng);
    std::vector<bool> expected(10, true);
    for (int i : { 1, 4, 6, 8 })
    {
      readings[i].range *= 0.4;  // an unknown obstacle in front of the sensor
      expected[i] = false;
    }
    const core::Result result = localizer.localize(readings);
    if (result.candidates.empty())
    {
      continue;
    }
    const core::Candidate& best = result.candidates.front();
    if ((best.pose.position() - q.position()).norm() < 0.01 &&
        std::abs(core::angleDiff(best.pose.theta, q.theta)) < 0.1 * core::kPi / 180.0)
    {
      ++found;
      flagged += best.inlier_mask == expected ? 1 : 0;
    }
  }
  EXPECT_GE(found, trials * 0.95);
  EXPECT_GE(flagged, trials * 0.95);
}

TEST(AdaptiveEngine, CentimetreAccuracyInA60By40Building)
{
  core::BuildingOptions building;
  building.width = 60.0;
  building.height = 40.0;
  building.seed = 3;
  const auto map = std::make_shared<const core::MapRayCaster>(core::generateBuilding(building));
  core::LocalizerOptions options;
  options.engine = core::Engine::Adaptive;
  options.resolution = 1500;  // 4 cm leaves
  options.theta_resolution = 720;
  options.max_candidates = 5;
  core::Localizer localizer(map, options);
  std::mt19937_64 rng(17);
  int good = 0;
  const int trials = 12;
  for (int trial = 0; trial < trials; ++trial)
  {
    const int k = 10 + trial % 7;  // k = 10 to 16
    const core::Pose2 q = randomFreePose(*map, rng);
    const core::Result result = localizer.localize(turnInPlace(*map, q, k, 0.0, rng));
    ASSERT_FALSE(result.truncated);
    if (!result.candidates.empty())
    {
      const core::Pose2& best = result.candidates.front().pose;
      good += ((best.position() - q.position()).norm() < 0.01 &&
               std::abs(core::angleDiff(best.theta, q.theta)) < 0.1 * core::kPi / 180.0)
                  ? 1
                  : 0;
    }
  }
  // A generated building repeats rooms, so a few poses are truly ambiguous.
  EXPECT_GE(good, trials - 1);
}
