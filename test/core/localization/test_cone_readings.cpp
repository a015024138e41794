// Cone readings (issue 18) in verification, polish and the adaptive box test: the box test
// stays conservative against a brute force over sampled poses, a zero half-angle is exactly the
// ray, the polish (and the localizer's candidate) finds the position of cone readings and says
// through the covariance when the heading is undetermined, and the adaptive engine keeps the
// truth with cone readings.
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/adaptive/adaptive_engine.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr double kDeg = kPi / 180.0;

/// k cone readings of half-angle @p half_angle turning in place at @p truth (exact).
std::vector<Reading> coneReadings(const MapRayCaster& map, const Pose2& truth, int k, double half_angle)
{
  std::vector<Reading> readings;
  for (const Pose2& g : test::inPlaceOffsets(k))
  {
    Reading r;
    r.offset = g;
    r.half_angle = half_angle;
    r.range = coneRange(map, compose(truth, g), half_angle);
    readings.push_back(r);
  }
  return readings;
}

Pose2 sampleIn(const PoseBox& box, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  return Pose2(box.x0 + unit(rng) * (box.x1 - box.x0), box.y0 + unit(rng) * (box.y1 - box.y0),
               box.t0 + unit(rng) * (box.t1 - box.t0));
}

TEST(ConeBoxTest, NoFalseNegativeAgainstSampledPoses)
{
  const auto map = test::loadMap("maps/office.poly");
  std::mt19937_64 rng(18);
  std::uniform_real_distribution<double> unit(0.0, 1.0), off(-0.3, 0.3);
  const double tolerance = 0.02;
  int explained_boxes = 0;
  for (int trial = 0; trial < 1500; ++trial)
  {
    const Pose2 centre = test::randomFreePose(*map, rng, 0.0);
    PoseBox box;
    box.x0 = centre.x - 0.3 * unit(rng);
    box.x1 = centre.x + 0.3 * unit(rng);
    box.y0 = centre.y - 0.3 * unit(rng);
    box.y1 = centre.y + 0.3 * unit(rng);
    box.t0 = centre.theta - 0.4 * unit(rng);
    box.t1 = centre.theta + 0.4 * unit(rng);
    Reading r;
    r.offset = Pose2(off(rng), off(rng), wrapAngle(8.0 * off(rng)));
    r.half_angle = trial % 5 == 0 ? kMaxConeHalfAngle : 0.5 * unit(rng);
    // Half the readings are measured from a pose of the box, half are any range.
    const Pose2 source = compose(sampleIn(box, rng), r.offset);
    r.range = trial % 2 == 0 && map->isFree(source.position()) ? coneRange(*map, source, r.half_angle) :
                                                                 0.1 + 6.0 * unit(rng);
    if (!std::isfinite(r.range))
    {
      continue;
    }
    bool explained = false;
    for (int s = 0; s < 200 && !explained; ++s)
    {
      const Pose2 sensor = compose(sampleIn(box, rng), r.offset);
      explained =
          map->isFree(sensor.position()) && std::abs(coneRange(*map, sensor, r.half_angle) - r.range) <= tolerance;
    }
    explained_boxes += explained ? 1 : 0;
    if (explained)
    {
      ASSERT_TRUE(readingMayExplain(*map, r, box, tolerance)) << "trial " << trial;
    }
  }
  EXPECT_GT(explained_boxes, 500);  // the test exercises the box test
}

TEST(ConeBoxTest, AnEdgeNearerInEveryConePrunesButNeverAPoseThatExplains)
{
  // Exact readings (tolerance 0) from a pose of a small box: the box always stays. Readings
  // longer than every sampled pose of the box sees (its cone meets a wall nearer): the box goes
  // more often than not, an edge inside every pose's cone being nearer.
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> unit(0.0, 1.0), off(-0.2, 0.2);
  int too_long = 0, pruned = 0;
  for (const char* name : { "maps/office.poly", "maps/apartment.poly" })
  {
    const auto map = test::loadMap(name);
    for (int trial = 0; trial < 4000; ++trial)
    {
      const Pose2 q = test::randomFreePose(*map, rng, 0.0);
      const double size = 0.002 + 0.1 * unit(rng);
      const PoseBox box{ q.x - size * unit(rng), q.x + size * unit(rng),     q.y - size * unit(rng),
                         q.y + size * unit(rng), q.theta - size * unit(rng), q.theta + size * unit(rng) };
      Reading r;
      r.offset = Pose2(off(rng), off(rng), wrapAngle(16.0 * off(rng)));
      r.half_angle = trial % 7 == 0 ? kMaxConeHalfAngle : 0.05 + 0.6 * unit(rng);
      const Pose2 sensor = compose(q, r.offset);
      r.range = coneRange(*map, sensor, r.half_angle);
      if (!map->isFree(sensor.position()) || !std::isfinite(r.range))
      {
        continue;
      }
      ASSERT_TRUE(readingMayExplain(*map, r, box, 0.0)) << name << " trial " << trial;
      r.range += 0.3 + unit(rng);
      double longest = 0.0;
      for (int s = 0; s < 100; ++s)
      {
        longest = std::max(longest, coneRange(*map, compose(sampleIn(box, rng), r.offset), r.half_angle));
      }
      if (longest < r.range - 0.1)
      {
        ++too_long;
        pruned += readingMayExplain(*map, r, box, 0.05) ? 0 : 1;
      }
    }
  }
  EXPECT_GT(too_long, 2000);
  EXPECT_GT(pruned, too_long / 2) << pruned << " of " << too_long;
}

TEST(ConeBoxTest, ZeroHalfAngleIsTheRayArc)
{
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> off(-0.3, 0.3), t(-kPi, kPi), unit(0.0, 1.0);
  for (int trial = 0; trial < 1000; ++trial)
  {
    Reading r;
    r.offset = Pose2(off(rng), off(rng), t(rng));
    r.range = 5.0 * unit(rng);
    const double t0 = t(rng);
    const double t1 = t0 + unit(rng);
    const Vec2 v(r.offset.x + r.range * std::cos(r.offset.theta), r.offset.y + r.range * std::sin(r.offset.theta));
    const Box2 ray = rotatedArcBounds(v, t0, t1);
    const Box2 arc = hitArcBounds(r, t0, t1);
    ASSERT_EQ(arc.min, ray.min);
    ASSERT_EQ(arc.max, ray.max);
  }
}

TEST(ConeEvaluation, ZeroHalfAngleIsTheRayCastAndConesUseTheConeCast)
{
  const auto map = test::loadMap("maps/office.poly");
  std::mt19937_64 rng(4);
  for (int trial = 0; trial < 50; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng);
    std::vector<Reading> rays = test::exactReadings(*map, truth, test::inPlaceOffsets(8));
    const PoseEvaluation at_truth = evaluatePose(*map, truth, rays, 0.05);
    ASSERT_EQ(at_truth.inliers, 8);
    const Pose2 moved(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.01);
    const PoseEvaluation eval = evaluatePose(*map, moved, rays, 0.05);
    for (std::size_t i = 0; i < rays.size(); ++i)
    {
      if (map->isFree(compose(moved, rays[i].offset).position()))
      {
        ASSERT_EQ(eval.residuals[i], map->range(compose(moved, rays[i].offset)) - rays[i].range);
      }
    }
    // The same readings as cones: the ray ranges are not the cones' (nearer points in the sector).
    const std::vector<Reading> cones = coneReadings(*map, truth, 8, 12.0 * kDeg);
    EXPECT_EQ(evaluatePose(*map, truth, cones, 0.01).inliers, 8);
    for (std::size_t i = 0; i < cones.size(); ++i)
    {
      ASSERT_LE(cones[i].range, rays[i].range + 1e-9);
    }
  }
}

TEST(ConePolish, FindsThePositionAndSaysWhenTheHeadingIsUndetermined)
{
  // A square 4 x 4 m room; a sensor at the centre of the robot, four 30 deg cones facing the
  // four walls: each cone's nearest point (the foot of the perpendicular) lies strictly inside
  // its sector, so the heading changes no reading.
  std::vector<Ring> rings{ { Vec2(0, 0), Vec2(4, 0), Vec2(4, 4), Vec2(0, 4) } };
  const MapRayCaster map(PolygonMap::fromRings(rings, "square"));
  const Pose2 truth(1.7, 2.2, 0.05);
  const std::vector<Reading> cones = coneReadings(map, truth, 4, 15.0 * kDeg);
  const PolishOutcome out =
      polishPose(map, Pose2(1.75, 2.15, 0.07), cones, std::vector<bool>(cones.size(), true), 0.0, 50, 0.001);
  EXPECT_LT(test::positionError(out.pose, truth), 1e-4);
  EXPECT_GT(out.covariance(2, 2), 1.0) << "the heading is undetermined: its variance must be large";
  EXPECT_LT(out.covariance(0, 0), 1e-5);
  EXPECT_LT(out.covariance(1, 1), 1e-5);
}

TEST(ConeLocalization, FacingFlatWallsTheCandidateSaysTheHeadingIsLoose)
{
  // A 5 x 3 m room; four readings 90 deg apart from the robot's centre, each facing a wall. With
  // 27 deg cones every nearest point is the foot of a perpendicular, inside its sector: the
  // heading changes no reading in a band of 27 deg, and the returned candidate's covariance must
  // say so. With 2 deg cones the bounding rays hit the walls and fix the heading.
  std::vector<Ring> rings{ { Vec2(0, 0), Vec2(5, 0), Vec2(5, 3), Vec2(0, 3) } };
  const auto map = std::make_shared<const MapRayCaster>(PolygonMap::fromRings(rings, "room"));
  const Pose2 truth(1.8, 1.2, 0.2);  // 11.5 deg off the walls' normals
  LocalizerOptions options;
  options.resolution = 64;
  options.threads = 1;
  Localizer localizer(map, options);
  double variance[2] = { 0.0, 0.0 };
  for (const int wide : { 1, 0 })
  {
    const Result result = localizer.localize(coneReadings(*map, truth, 4, (wide ? 13.5 : 1.0) * kDeg));
    const Candidate* nearest = test::nearestCandidate(result, truth);
    ASSERT_NE(nearest, nullptr);
    EXPECT_LT(test::positionError(nearest->pose, truth), 0.02) << "wide " << wide;
    EXPECT_LT(test::angleError(nearest->pose, truth), (wide ? 27.0 : 1.0) * kDeg) << "wide " << wide;
    EXPECT_LT(nearest->covariance(0, 0) + nearest->covariance(1, 1), 1e-3) << "wide " << wide;
    variance[wide] = nearest->covariance(2, 2);
  }
  EXPECT_GT(variance[1], std::pow(20.0 * kDeg, 2)) << "27 deg cones facing walls: the heading is loose";
  EXPECT_LT(variance[0], std::pow(2.0 * kDeg, 2)) << "2 deg cones: the bounding rays fix the heading";
}

/// One thread at resolution 64: the office localizations below.
LocalizerOptions officeOptions(Engine engine, Method method)
{
  LocalizerOptions options;
  options.engine = engine;
  options.method = method;
  options.threads = 1;
  options.resolution = 64;
  return options;
}

TEST(ConeLocalization, AdaptiveEngineFindsTheTruthWithConeReadings)
{
  const auto map = test::loadMap("maps/office.poly");
  AdaptiveEngine engine(map, officeOptions(Engine::Adaptive, Method::Robust));
  std::mt19937_64 rng(27);
  for (int trial = 0; trial < 3; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng, 0.2);
    const std::vector<Reading> cones = coneReadings(*map, truth, 10, 13.5 * kDeg);
    const Result result = engine.localize(cones);
    EXPECT_TRUE(test::truthInLeaves(engine.lastLeaves(), truth, 10)) << "trial " << trial;
    const Candidate* nearest = test::nearestCandidate(result, truth);
    ASSERT_NE(nearest, nullptr);
    EXPECT_LT(test::positionError(nearest->pose, truth), 0.05) << "trial " << trial;
  }
}

TEST(ConeLocalization, PaperMethodKeepsTheConesTruth)
{
  // The paper's sample test is for rays; a cone reading's set is its conservative preimage, so
  // the truth stays in M_k' with wide cones too (60 deg half-angle: with the ray's sample test
  // the truth left M_k' in 2 of 3 trials).
  const auto map = test::loadMap("maps/office.poly");
  LocalizerOptions options = officeOptions(Engine::Voxel, Method::Paper);
  options.min_inliers = 10;
  VoxelEngine engine(map, options);
  std::mt19937_64 rng(27);
  for (int trial = 0; trial < 3; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng, 0.2);
    engine.localize(coneReadings(*map, truth, 10, 60.0 * kDeg));
    EXPECT_TRUE(test::truthInSet(engine.grid(), engine.lastCount(), truth, 10)) << "trial " << trial;
  }
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
