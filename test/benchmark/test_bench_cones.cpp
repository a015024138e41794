// The protocol with cone readings (ProtocolOptions::half_angle, fdml_bench --fov): every reading
// is the nearest point of the map or a disc within its cone, against brute force (the map's
// edges one by one, each disc by a dense fan of rays); the trial is the same as with rays except
// for the ranges, which a cone can only shorten.
#include "fdml_localization/benchmark/benchmark_protocol.h"
#include "fdml_localization/core/map/map_io.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

namespace core = fdml_localization::core;

namespace
{

/// The nearest entry into the disc over a fan of rays spanning the cone (an upper bound).
double discFan(const core::Pose2& sensor, double half_angle, const core::Obstacle& disc)
{
  constexpr int kRays = 3000;
  double best = core::kInf;
  for (int i = 0; i <= kRays; ++i)
  {
    const double phi = sensor.theta - half_angle + 2.0 * half_angle * i / kRays;
    best = std::min(best, core::rayCircleDistance(sensor.position(), core::Vec2(std::cos(phi), std::sin(phi)),
                                                  disc.centre, disc.radius));
  }
  return best;
}
}  // namespace

TEST(BenchCones, ConeReadingsAreTheNearestPointInTheCone)
{
  const auto map = core::test::loadMap("maps/apartment.poly");
  core::ProtocolOptions options;
  options.obstacles = 30;
  options.half_angle = 0.5 * 27.0 * core::kPi / 180.0;
  options.max_range = 6.0;
  int obstacle_readings = 0;
  for (int t = 0; t < 8; ++t)
  {
    const core::Trial trial = core::generateTrial(map, options, core::trialSeed(5, "apartment", 30, t));
    for (std::size_t i = 0; i < trial.readings.size(); ++i)
    {
      const core::Reading& r = trial.readings[i];
      EXPECT_EQ(r.half_angle, options.half_angle);
      const core::Pose2 sensor = core::compose(trial.truth, r.offset);
      const double wall = core::coneRangeBruteForce(map->grid().segments(), sensor, r.half_angle, options.max_range);
      double disc = core::kInf;
      for (const core::Obstacle& o : trial.obstacles)
      {
        disc = std::min(disc, discFan(sensor, r.half_angle, o));
      }
      disc = disc <= options.max_range ? disc : core::kInf;
      // The fan's chord error on a 0.1 m disc within 6 m: below 1e-4 m.
      const double expected = std::min(wall, disc);
      if (std::isinf(expected))
      {
        EXPECT_TRUE(std::isinf(r.range)) << "trial " << t << " reading " << i;
        continue;
      }
      EXPECT_NEAR(r.range, expected, 1e-4) << "trial " << t << " reading " << i;
      if (std::abs(wall - disc) > 1e-3)
      {
        EXPECT_EQ(trial.hit_static[i], wall < disc) << "trial " << t << " reading " << i;
        obstacle_readings += wall < disc ? 0 : 1;
      }
    }
  }
  EXPECT_GT(obstacle_readings, 3);
}

TEST(BenchCones, ConesKeepTheTrialAndOnlyShortenTheReadings)
{
  const auto map = core::test::loadMap("maps/apartment.poly");
  core::ProtocolOptions rays;
  rays.obstacles = 10;
  rays.translate = true;
  core::ProtocolOptions cones = rays;
  cones.half_angle = 0.5 * 30.0 * core::kPi / 180.0;
  int shorter = 0;
  for (int t = 0; t < 10; ++t)
  {
    const std::uint64_t seed = core::trialSeed(9, "apartment", 10, t);
    const core::Trial a = core::generateTrial(map, rays, seed);
    const core::Trial b = core::generateTrial(map, cones, seed);
    ASSERT_EQ(a.readings.size(), b.readings.size());
    EXPECT_EQ(a.truth.x, b.truth.x);
    EXPECT_EQ(a.truth.theta, b.truth.theta);
    for (std::size_t i = 0; i < a.readings.size(); ++i)
    {
      EXPECT_EQ(a.readings[i].offset.x, b.readings[i].offset.x);
      EXPECT_EQ(a.readings[i].half_angle, 0.0);
      EXPECT_LE(b.readings[i].range, a.readings[i].range + 1e-12);
      shorter += b.readings[i].range < a.readings[i].range - 0.01 ? 1 : 0;
    }
  }
  EXPECT_GT(shorter, 10);
}

TEST(BenchCones, RejectsHalfAnglesOutsideTheHalfPlane)
{
  core::ProtocolOptions options;
  for (const double bad : { -0.01, core::kMaxConeHalfAngle + 1e-9, std::nan("") })
  {
    options.half_angle = bad;
    EXPECT_EQ(core::validate(options).size(), 1u) << bad;
    EXPECT_THROW(core::generateTrial(core::test::loadMap("maps/apartment.poly"), options, 1), std::invalid_argument);
  }
  options.half_angle = core::kMaxConeHalfAngle;
  EXPECT_TRUE(core::validate(options).empty());
}
