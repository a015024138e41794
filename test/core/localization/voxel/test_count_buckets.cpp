// The count fields by level (count_buckets.h) against brute forces: regional maxima of random
// fields, the buckets, and the screened conservative field of real localizations (its maxima
// those of a brute force, passing the box test; no pose of a lowered voxel explaining more).
#include "fdml_localization/core/localization/voxel/count_buckets.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::CorruptedLRoomRun;
using VoxelSets = std::set<std::vector<std::size_t>>;

/// The 26 neighbours of @p v (heading periodic), written out independently of forEachNeighbour().
std::vector<std::size_t> neighboursOf(const GridSpec& spec, std::size_t v)
{
  const int ix = static_cast<int>(v % spec.nx);
  const int iy = static_cast<int>((v / spec.nx) % spec.ny);
  const int it = static_cast<int>(v / (static_cast<std::size_t>(spec.nx) * spec.ny));
  std::vector<std::size_t> out;
  for (int dt : { -1, 0, 1 })
  {
    for (int dy : { -1, 0, 1 })
    {
      for (int dx : { -1, 0, 1 })
      {
        const int x = ix + dx;
        const int y = iy + dy;
        if ((dx || dy || dt) && x >= 0 && x < spec.nx && y >= 0 && y < spec.ny)
        {
          out.push_back(spec.index(x, y, (it + dt + spec.nt) % spec.nt));
        }
      }
    }
  }
  return out;
}

/// Brute force: the plateaus of count == level none of whose voxels has a higher neighbour.
VoxelSets bruteMaxima(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level)
{
  VoxelSets maxima;
  std::vector<char> done(count.size(), 0);
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    if (count[v] != level || done[v])
    {
      continue;
    }
    std::vector<std::size_t> plateau{ v };
    done[v] = 1;
    bool maximum = true;
    for (std::size_t i = 0; i < plateau.size(); ++i)
    {
      for (std::size_t w : neighboursOf(spec, plateau[i]))
      {
        maximum = maximum && count[w] <= level;
        if (count[w] == level && !done[w])
        {
          done[w] = 1;
          plateau.push_back(w);
        }
      }
    }
    std::sort(plateau.begin(), plateau.end());
    if (maximum)
    {
      maxima.insert(plateau);
    }
  }
  return maxima;
}

VoxelSets asSets(const std::vector<VoxelCluster>& clusters)
{
  VoxelSets sets;
  for (VoxelCluster c : clusters)
  {
    std::sort(c.voxels.begin(), c.voxels.end());
    sets.insert(c.voxels);
  }
  return sets;
}

/// liftNonMaximalPlateaus() at @p level lifts the rest of the level (@p at_level) off its maxima
/// (@p maxima), in ascending order.
void expectOffMaximaFound(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                          const std::vector<std::size_t>& at_level, const VoxelSets& maxima)
{
  std::set<std::size_t> off_maxima(at_level.begin(), at_level.end());
  for (const std::vector<std::size_t>& plateau : maxima)
  {
    for (std::size_t v : plateau)
    {
      off_maxima.erase(v);
    }
  }
  std::vector<std::uint8_t> lifted = count;
  const std::vector<std::size_t> lower = liftNonMaximalPlateaus(spec, lifted, level);
  EXPECT_EQ(lower, std::vector<std::size_t>(off_maxima.begin(), off_maxima.end())) << "level " << level;
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    ASSERT_EQ(lifted[v], off_maxima.count(v) ? level + 1 : count[v]) << "level " << level << " voxel " << v;
  }
}

TEST(CountBuckets, RegionalMaximaOfRandomFieldsMatchABruteForce)
{
  std::mt19937_64 rng(11);
  std::size_t found = 0;
  for (int trial = 0; trial < 48; ++trial)
  {
    // Rows of one, two and three 64-voxel words (the lift floods them as bit masks).
    const GridSpec spec = trial % 4 == 1 ? test::smallSpec(70, 5, 6) :
                          trial % 4 == 3 ? test::smallSpec(131, 3, 4) :
                                           test::smallSpec(14, 9, 8);
    // Random values, smoothed into plateaus and ridges by taking blocks of 2 x 2 x 1 alike.
    std::vector<std::uint8_t> count(spec.voxelCount());
    std::uniform_int_distribution<int> value(0, 5);
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      count[v] = static_cast<std::uint8_t>(value(rng));
    }
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      const int ix = static_cast<int>(v % spec.nx);
      const int iy = static_cast<int>((v / spec.nx) % spec.ny);
      const int it = static_cast<int>(v / (static_cast<std::size_t>(spec.nx) * spec.ny));
      count[v] = count[spec.index(ix - ix % 2, iy - iy % 2, it)];
    }
    CountBuckets buckets(count, spec.nx, 1, 5);
    for (int level = 5; level >= 1; --level)
    {
      std::vector<std::size_t> plain;
      for (std::size_t v = 0; v < count.size(); ++v)
      {
        if (count[v] == level)
        {
          plain.push_back(v);
        }
      }
      ASSERT_EQ(buckets.at(level), plain);
      const VoxelSets expected = bruteMaxima(spec, count, level);
      EXPECT_EQ(asSets(regionalMaxima(spec, count, level, plain)), expected) << "trial " << trial;
      expectOffMaximaFound(spec, count, level, plain, expected);
      found += expected.size();
    }
    EXPECT_TRUE(buckets.at(0).empty());
  }
  EXPECT_GT(found, 100u);
}

TEST(CountBuckets, TheScreenedFieldsMaximaPassTheBoxTestAndItStaysAnUpperBound)
{
  std::size_t lowered_total = 0;
  std::size_t returned_total = 0;
  for (std::uint64_t seed : { 1u, 2u, 3u, 4u })
  {
    const CorruptedLRoomRun run(seed);
    const GridSpec& spec = run.engine->grid();
    const std::vector<std::uint8_t>& count = run.engine->lastCount();
    const double tolerance = std::max(run.options.range_tolerance, run.options.agreement_tolerance);
    const BlockMaxima blocks(spec, count);
    ScreenedCount screened(spec, count, blocks);
    BoxConsensusTest test(*run.map, run.readings, tolerance);
    for (int level = 10; level >= 3; --level)
    {
      const VoxelSets returned = asSets(screened.maximaAt(level, BoxScreen{ *run.map, run.readings, tolerance, 2 }));
      const std::vector<std::uint8_t>& values = screened.values();
      // The maxima are the screened field's, and every voxel of them passes its box test.
      for (const std::vector<std::size_t>& plateau : returned)
      {
        for (std::size_t v : plateau)
        {
          ASSERT_TRUE(test.reaches(voxelBox(spec, v), level)) << "seed " << seed << " voxel " << v;
        }
      }
      EXPECT_EQ(returned, bruteMaxima(spec, values, level)) << "seed " << seed << " level " << level;
      returned_total += returned.size();
    }
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      ASSERT_LE(screened.values()[v], count[v]);
      if (screened.values()[v] < count[v] && screened.values()[v] >= 3)
      {
        // Lowered (a block holding it or its own box ruled the level above out): no pose of it
        // explains more readings (every 20th lowered voxel, sampled).
        if (lowered_total++ % 20 == 0)
        {
          EXPECT_LE(test::sampledConsensus(*run.map, run.readings, voxelBox(spec, v), tolerance), screened.values()[v])
              << "voxel " << v;
        }
      }
    }
  }
  EXPECT_GT(lowered_total, 100u);
  EXPECT_GT(returned_total, 0u);
}

TEST(CountBuckets, LevelsSkippedLeaveTheScreenedFieldsMaximaRight)
{
  const CorruptedLRoomRun run(5);
  const GridSpec& spec = run.engine->grid();
  const double tolerance = std::max(run.options.range_tolerance, run.options.agreement_tolerance);
  const BlockMaxima blocks(spec, run.engine->lastCount());
  ScreenedCount screened(spec, run.engine->lastCount(), blocks);
  std::size_t returned = 0;
  std::size_t lowered = 0;
  for (int level : { 9, 7, 6, 4 })
  {
    // Only the voxels of the level's maxima are screened: a voxel lowered was in one.
    const std::vector<std::uint8_t> before = screened.values();
    std::set<std::size_t> on_maxima;
    for (const std::vector<std::size_t>& plateau : bruteMaxima(spec, before, level))
    {
      on_maxima.insert(plateau.begin(), plateau.end());
    }
    const VoxelSets maxima = asSets(screened.maximaAt(level, BoxScreen{ *run.map, run.readings, tolerance, 2 }));
    EXPECT_EQ(maxima, bruteMaxima(spec, screened.values(), level)) << "level " << level;
    for (std::size_t v = 0; v < before.size(); ++v)
    {
      if (screened.values()[v] != before[v])
      {
        ++lowered;
        ASSERT_EQ(on_maxima.count(v), 1u) << "level " << level << " voxel " << v;
      }
    }
    returned += maxima.size();
  }
  EXPECT_GT(returned, 0u);
  EXPECT_GT(lowered, 0u);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
