// The box test over the voxel grid (box_screen.h) against a voxel-by-voxel box test and sampled
// poses, on count fields of real localizations: a voxel passes by its own box test, and one a
// block ruled out holds no pose explaining the level.
#include "fdml_localization/core/localization/voxel/box_screen.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::CorruptedLRoomRun;

// Each top block's largest count against a brute force, on grids whose sides are no multiple of
// the block's (partial blocks at the far edges).
TEST(BoxScreen, BlockMaximaAreEachTopBlocksLargestCount)
{
  std::mt19937_64 rng(17);
  for (const GridSpec& spec : { test::smallSpec(19, 13, 10), test::smallSpec(8, 16, 7), test::smallSpec(70, 3, 9) })
  {
    std::vector<std::uint8_t> count(spec.voxelCount());
    for (std::uint8_t& c : count)
    {
      c = static_cast<std::uint8_t>(rng() % 97 == 0 ? 1 + rng() % 11 : 0);  // sparse: one voxel makes a block
    }
    const BlockMaxima blocks(spec, count);
    const int side = BlockMaxima::kSide;
    ASSERT_EQ(blocks.blocksX(), (spec.nx + side - 1) / side);
    ASSERT_EQ(blocks.blocksY(), (spec.ny + side - 1) / side);
    const std::size_t nb =
        static_cast<std::size_t>(blocks.blocksX()) * blocks.blocksY() * ((spec.nt + side - 1) / side);
    std::vector<int> expected(nb, 0);
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      int ix = 0, iy = 0, it = 0;
      spec.unindex(v, ix, iy, it);
      const std::size_t b =
          (static_cast<std::size_t>(it / side) * blocks.blocksY() + iy / side) * blocks.blocksX() + ix / side;
      expected[b] = std::max<int>(expected[b], count[v]);
    }
    for (int level = 0; level <= 12; ++level)
    {
      std::vector<std::size_t> reaching;
      for (std::size_t b = 0; b < nb; ++b)
      {
        if (expected[b] >= level)
        {
          reaching.push_back(b);
        }
      }
      EXPECT_EQ(blocks.reaching(level), reaching) << "level " << level;
    }
  }
}

TEST(BoxScreen, ReachingLeavesAreTheVoxelsPassingTheirOwnBoxTest)
{
  for (std::uint64_t seed : { 1u, 2u, 3u })
  {
    const CorruptedLRoomRun run(seed);
    const GridSpec& spec = run.engine->grid();
    const std::vector<std::uint8_t>& count = run.engine->lastCount();
    for (int target : { 9, 7, 5, 3 })
    {
      BoxConsensusTest test(*run.map, run.readings, run.options.range_tolerance);
      std::vector<std::pair<std::size_t, int>> expected;
      std::size_t counted = 0;
      for (std::size_t v = 0; v < count.size(); ++v)
      {
        if (count[v] >= target)
        {
          ++counted;
          const int bound = std::min<int>(count[v], test.bound(voxelBox(spec, v), target));
          if (bound >= target)
          {
            expected.emplace_back(v, bound);
          }
        }
      }
      const std::vector<LeafBox> leaves =
          reachingLeaves(spec, count, target, BlockMaxima(spec, count),
                         BoxScreen{ *run.map, run.readings, run.options.range_tolerance, 2 });
      // The leaves are those voxels, in order, but for voxels a block ruled out (the box test is
      // sound but not monotone: a block's bound can be below a voxel's own): no pose there
      // explains the target.
      std::size_t j = 0;
      for (const auto& e : expected)
      {
        if (j < leaves.size() && spec.index(leaves[j].ix, leaves[j].iy, leaves[j].it) == e.first)
        {
          EXPECT_EQ(leaves[j++].count, e.second);
          continue;
        }
        EXPECT_LT(test::sampledConsensus(*run.map, run.readings, voxelBox(spec, e.first), run.options.range_tolerance),
                  target)
            << "voxel " << e.first;
      }
      EXPECT_EQ(j, leaves.size()) << "seed " << seed << " target " << target;
      EXPECT_GE(leaves.size(), expected.size() * 9 / 10);
      if (target == 3)
      {
        // The test has work to do: the box test rules out voxels the count lets through.
        EXPECT_LT(expected.size(), counted);
        EXPECT_GT(expected.size(), 0u);
      }
    }
  }
}

TEST(BoxScreen, EveryVoxelOfALevelGetsASoundVerdict)
{
  const CorruptedLRoomRun run(4);
  const GridSpec& spec = run.engine->grid();
  const std::vector<std::uint8_t>& count = run.engine->lastCount();
  std::size_t passed = 0;
  std::size_t failed = 0;
  for (int level = 9; level >= 4; --level)
  {
    std::vector<std::uint8_t> screened = count;
    const std::vector<VoxelVerdict> verdicts =
        screenLevel(spec, screened, level, BlockMaxima(spec, count), BoxScreen{ *run.map, run.readings, 0.05, 2 });
    BoxConsensusTest each(*run.map, run.readings, 0.05);
    std::size_t j = 0;
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      if (count[v] != level)
      {
        ASSERT_EQ(screened[v], count[v]) << "voxel " << v << " is off the level";
        continue;
      }
      // A voxel passes (in order) by its own box test; one lowered explains fewer readings.
      const PoseBox box = voxelBox(spec, v);
      if (j < verdicts.size() && verdicts[j].voxel == v)
      {
        EXPECT_TRUE(each.reaches(box, level)) << "level " << level << " voxel " << v;
        EXPECT_EQ(verdicts[j++].bound, each.bound(box, level));
        ASSERT_EQ(screened[v], level);
        ++passed;
        continue;
      }
      ASSERT_EQ(screened[v], level - 1) << "voxel " << v << " neither passed nor lowered";
      EXPECT_LT(test::sampledConsensus(*run.map, run.readings, box, 0.05), level) << "voxel " << v;
      ++failed;
    }
    EXPECT_EQ(j, verdicts.size()) << "level " << level;
  }
  EXPECT_GT(passed, 50u);
  EXPECT_GT(failed, 50u);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
