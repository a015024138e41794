// Exact readings on static maps: the truth lies in M_k' (conservativeness) and the polished
// candidate nearest to it is within 1 mm and 0.05 degrees; theta near +-pi; translation
// between readings and several sensors with mounting offsets.
#include "fdml_localization/core/localization/adaptive/adaptive_engine.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <cstdio>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::angleError;
using test::positionError;

constexpr double kDeg = kPi / 180.0;

struct AccuracyStats
{
  int trials = 0;
  int in_set = 0;
  int accurate = 0;
  int top1 = 0;
  int continuum = 0;
  double candidates = 0.0;
};

AccuracyStats runExactTrials(Engine engine_kind, const std::shared_ptr<const MapRayCaster>& map, int resolution,
                             int trials, std::uint64_t seed)
{
  LocalizerOptions options;
  options.engine = engine_kind;
  options.resolution = resolution;
  options.threads = 1;  // many short calls: keep the suite fast on a loaded machine
  VoxelEngine voxel(map, options);
  AdaptiveEngine adaptive(map, options);
  LocalizerEngine& engine = engine_kind == Engine::Voxel ? static_cast<LocalizerEngine&>(voxel) : adaptive;
  std::mt19937_64 rng(seed);
  AccuracyStats stats;
  const std::vector<Pose2> offsets = test::inPlaceOffsets(10);
  for (int trial = 0; trial < trials; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng);
    const std::vector<Reading> readings = test::exactReadings(*map, truth, offsets);
    validateReadings(readings, options);
    const Result result = engine.localize(readings);
    ++stats.trials;
    stats.candidates += static_cast<double>(result.candidates.size());
    const bool kept = engine_kind == Engine::Voxel ?
                          test::truthInSet(voxel.grid(), voxel.lastCount(), truth, result.min_inliers_used) :
                          test::truthInLeaves(adaptive.lastLeaves(), truth, result.min_inliers_used);
    if (kept)
    {
      ++stats.in_set;
    }
    const Candidate* nearest = test::nearestCandidate(result, truth);
    if (nearest && positionError(nearest->pose, truth) < 1e-3 && angleError(nearest->pose, truth) < 0.05 * kDeg)
    {
      ++stats.accurate;
    }
    else if (nearest && positionError(nearest->pose, truth) < 0.5 && angleError(nearest->pose, truth) < 0.05 * kDeg &&
             nearest->inliers == static_cast<int>(readings.size()) && nearest->rms_residual < 1e-9)
    {
      // All readings hit walls parallel to one direction: the truth lies on a continuum of
      // exact solutions, and the candidate found is another point of it, just as exact.
      ++stats.accurate;
      ++stats.continuum;
    }
    if (!result.candidates.empty() && positionError(result.candidates[0].pose, truth) < 1e-3 &&
        angleError(result.candidates[0].pose, truth) < 0.05 * kDeg)
    {
      ++stats.top1;
    }
  }
  std::printf("[ STATS    ] n=%d trials=%d in M_k'=%d nearest within 1 mm/0.05 deg=%d (%d of them on an exact "
              "continuum) top-1=%d mean candidates=%.2f\n",
              resolution, stats.trials, stats.in_set, stats.accurate, stats.continuum, stats.top1,
              stats.candidates / std::max(1, stats.trials));
  return stats;
}

void expectConservativeAndAccurate(const AccuracyStats& stats)
{
  EXPECT_GE(stats.in_set, static_cast<int>(std::ceil(0.99 * stats.trials)));
  EXPECT_GE(stats.accurate, static_cast<int>(std::ceil(0.99 * stats.trials)));
}

/// The shared correctness tests run on both engines.
class LocalizerAccuracy : public ::testing::TestWithParam<Engine>
{};

TEST_P(LocalizerAccuracy, LRoomExactReadings)
{
  expectConservativeAndAccurate(runExactTrials(GetParam(), test::lRoomMap(), 64, 500, 11));
}

TEST_P(LocalizerAccuracy, OfficeExactReadings)
{
  expectConservativeAndAccurate(runExactTrials(GetParam(), test::loadMap("maps/office.poly"), 100, 500, 12));
}

TEST_P(LocalizerAccuracy, PoseNearPiIsOneCandidateAtTheRightAngle)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.engine = GetParam();
  options.resolution = 64;
  Localizer localizer(map, options);
  for (double theta : { kPi - 0.004, -kPi + 0.004, kPi - 1e-9 })
  {
    const Pose2 truth(1.3, 4.1, theta);
    const Result result = localizer.localize(test::exactReadings(*map, truth, test::inPlaceOffsets(10)));
    ASSERT_FALSE(result.candidates.empty());
    int near_truth = 0;
    for (const Candidate& c : result.candidates)
    {
      if (positionError(c.pose, truth) < 0.5)
      {
        ++near_truth;
        EXPECT_LT(angleError(c.pose, truth), 0.05 * kDeg) << "theta " << c.pose.theta;
        EXPECT_GT(std::abs(c.pose.theta), 3.0);
      }
    }
    EXPECT_EQ(near_truth, 1);
    EXPECT_LT(positionError(result.candidates[0].pose, truth), 1e-3);
  }
}

/// Readings taken while the robot drives (odometry g_i), by three sensors with mounting offsets.
std::vector<Pose2> movingMultiSensorOffsets()
{
  const std::vector<Pose2> mounts = { Pose2(0.20, 0.0, 0.0), Pose2(-0.15, 0.10, 2.2), Pose2(0.0, -0.12, -1.7) };
  std::vector<Pose2> offsets;
  for (int step = 0; step < 4; ++step)
  {
    const Pose2 odom(0.15 * step, 0.03 * step, 0.35 * step);
    for (const Pose2& mount : mounts)
    {
      offsets.push_back(compose(odom, mount));
    }
  }
  return offsets;
}

TEST_P(LocalizerAccuracy, TranslationBetweenReadingsAndSeveralSensors)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.engine = GetParam();
  options.resolution = 64;
  Localizer localizer(map, options);
  std::mt19937_64 rng(5);
  const std::vector<Pose2> offsets = movingMultiSensorOffsets();
  int found = 0;
  const int trials = 40;
  for (int trial = 0; trial < trials; ++trial)
  {
    // Every sensor pose along the path must be in free space.
    Pose2 truth;
    for (;;)
    {
      truth = test::randomFreePose(*map, rng, 0.1);
      bool all_free = true;
      for (const Pose2& g : offsets)
      {
        all_free = all_free && map->isFree(compose(truth, g).position());
      }
      if (all_free)
      {
        break;
      }
    }
    const Result result = localizer.localize(test::exactReadings(*map, truth, offsets));
    const Candidate* nearest = test::nearestCandidate(result, truth);
    if (nearest && positionError(nearest->pose, truth) < 1e-3 && angleError(nearest->pose, truth) < 0.05 * kDeg &&
        nearest->inliers == static_cast<int>(offsets.size()))
    {
      ++found;
    }
  }
  std::printf("[ STATS    ] moving multi-sensor: %d / %d found\n", found, trials);
  EXPECT_GE(found, trials - 1);
}

INSTANTIATE_TEST_SUITE_P(Engines, LocalizerAccuracy, ::testing::Values(Engine::Voxel, Engine::Adaptive),
                         [](const ::testing::TestParamInfo<Engine>& info) {
                           return std::string(toString(info.param));
                         });

}  // namespace
}  // namespace core
}  // namespace fdml_localization
