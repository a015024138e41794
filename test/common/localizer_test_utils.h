// Shared helpers of the localizer tests: maps, random poses and simulated readings.
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace test
{
/// A small grid spec (0.1 m cells) for unit tests of voxel sets.
inline GridSpec smallSpec(int nx, int ny, int nt)
{
  GridSpec spec;
  spec.origin_x = -1.0;
  spec.origin_y = -2.0;
  spec.cell = 0.1;
  spec.nx = nx;
  spec.ny = ny;
  spec.nt = nt;
  return spec;
}

/// A fresh temporary folder for this test process.
inline std::string tempDir(const std::string& name)
{
  const auto dir =
      std::filesystem::temp_directory_path() / ("fdml_localizer_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

/// An L-shaped 8 x 6 m room with a square pillar and a triangular obstacle.
inline std::shared_ptr<const MapRayCaster> lRoomMap()
{
  std::vector<Ring> rings;
  rings.push_back({ Vec2(0, 0), Vec2(8, 0), Vec2(8, 4), Vec2(5, 4), Vec2(5, 6), Vec2(0, 6) });
  rings.push_back({ Vec2(2, 2), Vec2(2.6, 2), Vec2(2.6, 2.6), Vec2(2, 2.6) });
  rings.push_back({ Vec2(6, 1), Vec2(7, 1), Vec2(6.5, 2.2) });
  return std::make_shared<const MapRayCaster>(PolygonMap::fromRings(rings, "l_room"));
}

inline std::shared_ptr<const MapRayCaster> loadMap(const std::string& relative)
{
  return std::make_shared<const MapRayCaster>(loadPolyFile(std::string(FDML_SOURCE_DIR) + "/" + relative));
}

/// Squared distance from @p p to the nearest map edge [m^2].
inline double clearance2(const MapRayCaster& map, const Vec2& p)
{
  double best = kInf;
  for (const Segment& s : map.map().edges())
  {
    best = std::min(best, pointSegmentDistanceSquared(p, s));
  }
  return best;
}

/// A uniformly random pose in free space at least @p clearance [m] from every edge.
inline Pose2 randomFreePose(const MapRayCaster& map, std::mt19937_64& rng, double clearance = 0.05)
{
  const Box2& b = map.map().bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x());
  std::uniform_real_distribution<double> uy(b.min.y(), b.max.y());
  std::uniform_real_distribution<double> ut(-kPi, kPi);
  for (;;)
  {
    const Vec2 p(ux(rng), uy(rng));
    if (map.isFree(p) && clearance2(map, p) > clearance * clearance)
    {
      return Pose2(p.x(), p.y(), ut(rng));
    }
  }
}

/// Exact readings for the given sensor offsets from @p truth.
inline std::vector<Reading> exactReadings(const MapRayCaster& map, const Pose2& truth,
                                          const std::vector<Pose2>& offsets)
{
  std::vector<Reading> readings;
  for (const Pose2& g : offsets)
  {
    Reading r;
    r.offset = g;
    r.range = map.range(compose(truth, g));
    readings.push_back(r);
  }
  return readings;
}

/// The refinement settings of the continuum tests (settleAlongContinua(), gainAlongContinuum()):
/// eps 5 cm, noise 1 cm.
inline RefinementSettings continuumSettings()
{
  RefinementSettings settings;
  settings.agreement_tolerance = 0.05;
  settings.noise_sigma = 0.01;
  return settings;
}

/// k readings in place, 2 pi / k apart (the paper's protocol).
inline std::vector<Pose2> inPlaceOffsets(int k)
{
  std::vector<Pose2> offsets;
  for (int i = 0; i < k; ++i)
  {
    offsets.emplace_back(0.0, 0.0, wrapAngle(kTwoPi * i / k));
  }
  return offsets;
}

inline double positionError(const Pose2& a, const Pose2& b)
{
  return std::hypot(a.x - b.x, a.y - b.y);
}

inline double angleError(const Pose2& a, const Pose2& b)
{
  return std::abs(angleDiff(a.theta, b.theta));
}

/// The candidate nearest to @p truth (position plus 1 m per rad), or nullptr.
inline const Candidate* nearestCandidate(const Result& result, const Pose2& truth)
{
  const Candidate* best = nullptr;
  double best_d = kInf;
  for (const Candidate& c : result.candidates)
  {
    const double d = positionError(c.pose, truth) + angleError(c.pose, truth);
    if (d < best_d)
    {
      best_d = d;
      best = &c;
    }
  }
  return best;
}

/// True when the voxel of @p truth or one of its 26 neighbours has count >= level.
inline bool truthInSet(const GridSpec& spec, const std::vector<std::uint8_t>& count, const Pose2& truth, int level)
{
  int ix = 0;
  int iy = 0;
  int it = 0;
  if (!spec.locate(truth, ix, iy, it))
  {
    return false;
  }
  bool found = count[spec.index(ix, iy, it)] >= level;
  forEachNeighbour(spec, ix, iy, it, [&](std::size_t v) { found = found || count[v] >= level; });
  return found;
}

/// True when a leaf box of the adaptive search with count >= level holds @p truth.
inline bool truthInLeaves(const std::vector<LeafBox>& leaves, const Pose2& truth, int level)
{
  for (const LeafBox& leaf : leaves)
  {
    const PoseBox& b = leaf.box;
    if (leaf.count >= level && truth.x >= b.x0 && truth.x <= b.x1 && truth.y >= b.y0 && truth.y <= b.y1 &&
        truth.theta >= b.t0 && truth.theta <= b.t1)
    {
      return true;
    }
  }
  return false;
}

/// The most readings any of @p per_axis^3 poses spread over @p box (corners included) explains
/// within @p tolerance [m] (readingResidual()): a lower bound of the box's consensus, which a
/// sound upper bound (the box test, a count field) never falls below.
inline int sampledConsensus(const MapRayCaster& map, const std::vector<Reading>& readings, const PoseBox& box,
                            double tolerance, int per_axis = 3)
{
  int best = 0;
  for (int i = 0; i < per_axis * per_axis * per_axis; ++i)
  {
    const auto at = [&](double lo, double hi, int j) { return lo + (hi - lo) * j / (per_axis - 1); };
    const Pose2 pose(at(box.x0, box.x1, i % per_axis), at(box.y0, box.y1, (i / per_axis) % per_axis),
                     at(box.t0, box.t1, i / (per_axis * per_axis)));
    int explained = 0;
    for (const Reading& r : readings)
    {
      const double residual = readingResidual(map, pose, r);
      explained += std::abs(residual) <= tolerance ? 1 : 0;
    }
    best = std::max(best, explained);
  }
  return best;
}

/// A voxel engine's localization of ten readings in a circle, three of them corrupted, from a
/// random pose in the L room (resolution 40 x 32): its conservative count field and readings.
struct CorruptedLRoomRun
{
  std::shared_ptr<const MapRayCaster> map = lRoomMap();
  LocalizerOptions options;
  std::unique_ptr<VoxelEngine> engine;
  std::vector<Reading> readings;

  explicit CorruptedLRoomRun(std::uint64_t seed)
  {
    options.resolution = 40;
    options.theta_resolution = 32;
    options.threads = 2;
    engine = std::make_unique<VoxelEngine>(map, options);
    std::mt19937_64 rng(seed);
    std::vector<Pose2> offsets;
    for (int i = 0; i < 10; ++i)
    {
      offsets.emplace_back(0.0, 0.0, kTwoPi * i / 10);
    }
    readings = exactReadings(*map, randomFreePose(*map, rng, 0.2), offsets);
    std::uniform_real_distribution<double> wrong(0.3, 4.0);
    for (int i : { 1, 4, 7 })
    {
      readings[i].range = wrong(rng);
    }
    engine->localize(readings);
  }
};

}  // namespace test
}  // namespace core
}  // namespace fdml_localization
