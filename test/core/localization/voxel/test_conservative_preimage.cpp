// The voxel engine's preimage test never prunes the truth's voxel (docs/METHOD.md): brute force
// over maps, poses, sensor offsets, rays grazing map corners, no-return and cone readings.
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>
#include <string>

namespace fdml_localization
{
namespace core
{
namespace
{
/// A random room with up to three random triangular or quadrilateral obstacles.
std::shared_ptr<const MapRayCaster> randomMap(std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> size(3.0, 8.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (;;)
  {
    const double w = size(rng);
    const double h = size(rng);
    std::vector<Ring> rings{ { Vec2(0, 0), Vec2(w, 0), Vec2(w, h), Vec2(0, h) } };
    const int holes = static_cast<int>(unit(rng) * 4);
    for (int k = 0; k < holes; ++k)
    {
      const Vec2 c(0.5 + unit(rng) * (w - 1.0), 0.5 + unit(rng) * (h - 1.0));
      const int n = unit(rng) < 0.5 ? 3 : 4;
      Ring ring;
      const double phase = unit(rng) * kTwoPi;
      for (int i = 0; i < n; ++i)
      {
        const double a = phase + kTwoPi * i / n;
        const double r = 0.1 + 0.4 * unit(rng);
        ring.emplace_back(c.x() + r * std::cos(a), c.y() + r * std::sin(a));
      }
      rings.push_back(ring);
    }
    if (validateRings(rings).empty())
    {
      return std::make_shared<const MapRayCaster>(PolygonMap::fromRings(rings, "random"));
    }
  }
}

/// The truth's heading turned so that the sensor's ray (or cone edge) passes @p delta [rad] beside
/// a map vertex seen from the sensor: a ray grazing a corner.
Pose2 grazingTruth(const MapRayCaster& map, Pose2 truth, const Pose2& g, std::mt19937_64& rng)
{
  const std::vector<Segment>& edges = map.map().edges();
  const Vec2 vertex = edges[std::uniform_int_distribution<std::size_t>(0, edges.size() - 1)(rng)].a;
  const double delta = std::uniform_real_distribution<double>(-1e-4, 1e-4)(rng);
  for (int iteration = 0; iteration < 4; ++iteration)
  {
    const Pose2 s = compose(truth, g);
    truth.theta = wrapAngle(std::atan2(vertex.y() - s.y, vertex.x() - s.x) + delta - g.theta);
  }
  return truth;
}

/// Exact readings (cone readings of random half-angles up to @p max_half_angle, 10 % without a
/// return within a random max range) from the sensors in free space.
std::vector<Reading> exactConeReadings(const MapRayCaster& map, const Pose2& truth, const std::vector<Pose2>& offsets,
                                       double max_half_angle, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Reading> readings;
  for (const Pose2& g : offsets)
  {
    const Pose2 sensor = compose(truth, g);
    if (!map.isFree(sensor.position()))
    {
      continue;  // a sensor inside a wall measures nothing
    }
    Reading r;
    r.offset = g;
    r.half_angle = max_half_angle > 0.0 ? unit(rng) * max_half_angle : 0.0;
    r.range = coneRange(map, sensor, r.half_angle);
    if (unit(rng) < 0.1)
    {
      r.max_range = r.range * (0.5 + 0.5 * unit(rng));
      r.range = kInf;
    }
    readings.push_back(r);
  }
  return readings;
}

struct Trial
{
  std::size_t readings = 0;
  std::size_t missed = 0;
};

/// Exact readings of random truths through @p offsets (plus grazing variants); counts the
/// readings whose preimage misses the truth's voxel.
Trial runTrials(const std::shared_ptr<const MapRayCaster>& map, int resolution, int poses, double max_half_angle,
                std::mt19937_64& rng)
{
  LocalizerOptions options;
  options.resolution = resolution;
  options.range_tolerance = 0.0;  // exact readings: the bounds alone must hold the truth
  VoxelEngine engine(map, options);
  const GridSpec& spec = engine.grid();
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const std::vector<Pose2> four = { Pose2(0.15, 0, 0), Pose2(0, 0.15, kPi / 2), Pose2(-0.15, 0, kPi),
                                    Pose2(0, -0.15, -kPi / 2) };
  Trial trial;
  for (int n = 0; n < poses; ++n)
  {
    std::vector<Pose2> offsets = four;
    offsets.emplace_back((unit(rng) - 0.5) * 2.0, (unit(rng) - 0.5) * 2.0, (unit(rng) - 0.5) * kTwoPi);
    offsets.emplace_back(0.0, 0.0, (unit(rng) - 0.5) * kTwoPi);
    Pose2 truth = test::randomFreePose(*map, rng, 0.02);
    if (n % 2 == 1)
    {
      truth = grazingTruth(*map, truth, offsets[n % offsets.size()], rng);
    }
    const std::vector<Reading> readings = exactConeReadings(*map, truth, offsets, max_half_angle, rng);
    int ix = 0;
    int iy = 0;
    int it = 0;
    if (readings.empty() || !spec.locate(truth, ix, iy, it))
    {
      continue;
    }
    const std::vector<VoxelSet> sets = engine.preimages(readings);
    for (std::size_t i = 0; i < sets.size(); ++i)
    {
      ++trial.readings;
      if (!sets[i].test(ix, iy, it))
      {
        ++trial.missed;
        ADD_FAILURE() << "truth (" << truth.x << ", " << truth.y << ", " << truth.theta << ") offset ("
                      << readings[i].offset.x << ", " << readings[i].offset.y << ", " << readings[i].offset.theta
                      << ") range " << readings[i].range << " half-angle " << readings[i].half_angle;
      }
    }
  }
  return trial;
}

TEST(ConservativePreimage, GrazingRayKeepsTheTruth)
{
  // The ray from (1, 2.3) towards the pillar's corner (2, 2.6), 1e-5 rad to its left, passes the
  // corner and ends on the far wall; a hair to the right it stops on the pillar 1.04 m away.
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 32;
  options.range_tolerance = 0.0;
  VoxelEngine engine(map, options);
  const Vec2 p(1.0, 2.3);
  const double heading = std::atan2(2.6 - p.y(), 2.0 - p.x());
  for (double delta : { 1e-5, -1e-5 })
  {
    const Pose2 truth(p.x(), p.y(), heading + delta);
    Reading r;
    r.range = map->range(truth);
    int ix = 0;
    int iy = 0;
    int it = 0;
    ASSERT_TRUE(engine.grid().locate(truth, ix, iy, it));
    EXPECT_TRUE(engine.preimages({ r })[0].test(ix, iy, it)) << "delta " << delta << " range " << r.range;
  }
}

TEST(ConservativePreimage, TruthNeverPrunedOnBundledMaps)
{
  std::mt19937_64 rng(16);
  for (const std::string name :
       { "maps/l_room.poly", "maps/square_room.poly", "maps/apartment.poly", "maps/office.poly", "maps/corridor.poly" })
  {
    const Trial t = runTrials(test::loadMap(name), 40, 150, 0.0, rng);
    std::printf("[ STATS    ] %s: truth's voxel missed by %zu of %zu preimages\n", name.c_str(), t.missed, t.readings);
    EXPECT_EQ(t.missed, 0u) << name << ": " << t.missed << " of " << t.readings;
    EXPECT_GT(t.readings, 700u) << name;
  }
}

TEST(ConservativePreimage, TruthNeverPrunedOnRandomMaps)
{
  std::mt19937_64 rng(1616);
  std::size_t readings = 0;
  for (int m = 0; m < 10; ++m)
  {
    const Trial t = runTrials(randomMap(rng), 24 + 8 * (m % 4), 100, 0.0, rng);
    EXPECT_EQ(t.missed, 0u) << "map " << m << ": " << t.missed << " of " << t.readings;
    readings += t.readings;
  }
  std::printf("[ STATS    ] random maps: %zu preimages\n", readings);
  EXPECT_GT(readings, 4000u);
}

TEST(ConservativePreimage, ConeReadingsKeepTheTruth)
{
  std::mt19937_64 rng(18);
  for (int m = 0; m < 4; ++m)
  {
    const auto map = m == 0 ? test::loadMap("maps/apartment.poly") : randomMap(rng);
    const Trial t = runTrials(map, 32, 100, 0.5, rng);
    std::printf("[ STATS    ] cones, map %d: truth's voxel missed by %zu of %zu preimages\n", m, t.missed, t.readings);
    EXPECT_EQ(t.missed, 0u) << "map " << m << ": " << t.missed << " of " << t.readings;
    EXPECT_GT(t.readings, 400u);
  }
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
