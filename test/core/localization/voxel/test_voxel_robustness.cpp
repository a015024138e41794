// Float-to-integer conversions of the voxel engine (issue 15, item 1): readings whose offsets or
// ranges are far outside the grid neither crash nor hide the truth the other readings show.
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
TEST(VoxelRobustness, HugeOffsetsGiveEmptyPreimages)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 16;
  VoxelEngine engine(map, options);
  std::vector<Reading> readings;
  for (double big : { 1e9, -1e9, 1e18, 3e38, 1e300, -1e300 })
  {
    Reading r;
    r.offset = Pose2(big, 0.0, 4.0);
    r.range = 1.0;
    readings.push_back(r);
    r.offset = Pose2(0.5, -big, big);
    readings.push_back(r);
  }
  for (const VoxelSet& set : engine.preimages(readings))
  {
    EXPECT_EQ(set.count(), 0u);
  }
  int ix = 0;
  int iy = 0;
  int it = 0;
  EXPECT_FALSE(engine.grid().locate(Pose2(1e300, 0.0, 0.0), ix, iy, it));
  EXPECT_FALSE(engine.grid().locate(Pose2(0.0, -1e19, 0.0), ix, iy, it));
  EXPECT_TRUE(engine.grid().locate(Pose2(1.0, 1.0, 1e18), ix, iy, it));
  EXPECT_TRUE(it >= 0 && it < engine.grid().nt);
}

TEST(VoxelRobustness, HugeRangeIsAnOrdinaryReading)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 16;
  VoxelEngine engine(map, options);
  // Longer than any distance in the map: both keep only the voxels whose bound is unknown.
  Reading huge;
  huge.range = 1e300;
  Reading far;
  far.range = 1e6;
  const std::vector<VoxelSet> sets = engine.preimages({ huge, far });
  EXPECT_TRUE(sets[0] == sets[1]);
  EXPECT_LT(sets[0].count(), engine.grid().voxelCount() / 2);
}

/// The reproduction (square room, resolution 16) and the same on the L room, where the
/// other readings determine the pose: no crash, and the truth is still found.
TEST(VoxelRobustness, LocalizerSurvivesAHugeOffsetReading)
{
  {
    Localizer localizer(test::loadMap("maps/square_room.poly"), [] {
      LocalizerOptions o;
      o.resolution = 16;
      return o;
    }());
    std::vector<Reading> readings(3);
    readings[0].offset = Pose2(0, 0, 0);
    readings[1].offset = Pose2(0, 0, 2);
    readings[2].offset = Pose2(1e9, 0, 4);
    for (Reading& r : readings)
    {
      r.range = 1.0;
    }
    EXPECT_NO_THROW(localizer.localize(readings));
  }
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 64;
  Localizer localizer(map, options);
  std::mt19937_64 rng(15);
  for (int trial = 0; trial < 5; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng, 0.2);
    std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(8));
    Reading far;
    far.offset = Pose2(1e9, -3e9, 4.0);
    far.range = 1.0;
    readings.insert(readings.begin() + 3, far);
    const Result result = localizer.localize(readings);
    const Candidate* best = test::nearestCandidate(result, truth);
    ASSERT_NE(best, nullptr);
    EXPECT_LT(test::positionError(best->pose, truth), 0.05);
    EXPECT_LT(test::angleError(best->pose, truth), 0.035);
    EXPECT_GE(best->inliers, 8);
  }
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
