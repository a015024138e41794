// Component sizes flooded as bit masks (level_masks.h), and the components themselves
// (connectedComponents()), against a voxel-by-voxel flood written out here, on random fields
// with components of every shape, including grids of one and two headings (the heading's
// neighbours wrap onto the same row) and rows of one, two and three 64-voxel words.
#include "fdml_localization/core/localization/level_masks.h"

#include "fdml_localization/core/localization/components.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Brute force: the size of the component of {count >= level} holding each voxel (26 neighbours,
/// heading periodic), by a plain flood over every voxel.
std::vector<std::size_t> bruteSizes(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level)
{
  std::vector<long> label(count.size(), -1);
  std::vector<std::size_t> size_of;
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    if (count[v] < level || label[v] >= 0)
    {
      continue;
    }
    std::vector<std::size_t> queue{ v };
    label[v] = static_cast<long>(size_of.size());
    for (std::size_t head = 0; head < queue.size(); ++head)
    {
      const std::size_t u = queue[head];
      const int ix = static_cast<int>(u % spec.nx);
      const int iy = static_cast<int>((u / spec.nx) % spec.ny);
      const int it = static_cast<int>(u / (static_cast<std::size_t>(spec.nx) * spec.ny));
      for (int dt = -1; dt <= 1; ++dt)
      {
        for (int dy = -1; dy <= 1; ++dy)
        {
          for (int dx = -1; dx <= 1; ++dx)
          {
            const int x = ix + dx;
            const int y = iy + dy;
            if (x < 0 || x >= spec.nx || y < 0 || y >= spec.ny)
            {
              continue;
            }
            const std::size_t w = spec.index(x, y, (it + dt + spec.nt) % spec.nt);
            if (count[w] >= level && label[w] < 0)
            {
              label[w] = label[v];
              queue.push_back(w);
            }
          }
        }
      }
    }
    size_of.push_back(queue.size());
  }
  std::vector<std::size_t> sizes(count.size(), 0);
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    sizes[v] = label[v] < 0 ? 0 : size_of[static_cast<std::size_t>(label[v])];
  }
  return sizes;
}

/// connectedComponents() covers the voxels reaching @p level once each, a cluster for each
/// component of the brute force (@p expected: each voxel's component size).
void expectComponentsMatch(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                           const std::vector<std::size_t>& expected)
{
  std::set<std::size_t> covered;
  for (const VoxelCluster& cluster : connectedComponents(spec, count, level))
  {
    for (std::size_t v : cluster.voxels)
    {
      ASSERT_EQ(expected[v], cluster.voxels.size()) << "level " << level << " voxel " << v;
      covered.insert(v);
    }
  }
  const auto reaching = std::count_if(count.begin(), count.end(), [&](std::uint8_t c) { return c >= level; });
  EXPECT_EQ(covered.size(), static_cast<std::size_t>(reaching)) << "level " << level;
}

TEST(LevelMasks, ComponentSizesMatchAVoxelFlood)
{
  std::mt19937_64 rng(29);
  std::size_t largest = 0;
  for (const GridSpec& spec : { test::smallSpec(23, 11, 9), test::smallSpec(9, 7, 1), test::smallSpec(17, 5, 2),
                                test::smallSpec(70, 4, 6), test::smallSpec(64, 3, 3), test::smallSpec(150, 3, 2) })
  {
    for (int trial = 0; trial < 12; ++trial)
    {
      // Runs of random lengths and values: long runs (across 64-voxel words), gaps of one
      // voxel, single voxels.
      std::vector<std::uint8_t> count(spec.voxelCount());
      const std::size_t longest = trial % 4 == 3 ? 90 : trial % 3 == 0 ? 12 : 3;
      for (std::size_t v = 0; v < count.size();)
      {
        const std::size_t length = 1 + rng() % longest;
        const std::uint8_t value = static_cast<std::uint8_t>(rng() % 6);
        for (std::size_t j = 0; j < length && v < count.size(); ++j)
        {
          count[v++] = value;
        }
      }
      for (int level : { 0, 1, 3, 5, 6, 200 })
      {
        const std::vector<std::size_t> expected = bruteSizes(spec, count, level);
        std::vector<std::size_t> voxels(count.size());
        for (std::size_t v = 0; v < voxels.size(); ++v)
        {
          voxels[v] = (v * 7919u) % voxels.size();  // all of them, in scattered order
        }
        voxels.push_back(count.size());  // outside the grid: 0
        const std::vector<std::size_t> sizes = componentSizes(spec, count, level, voxels);
        ASSERT_EQ(sizes.size(), voxels.size());
        for (std::size_t k = 0; k + 1 < voxels.size(); ++k)
        {
          ASSERT_EQ(sizes[k], expected[voxels[k]]) << "level " << level << " voxel " << voxels[k];
        }
        EXPECT_EQ(sizes.back(), 0u);
        expectComponentsMatch(spec, count, level, expected);
        EXPECT_EQ(componentSize(spec, count, level, voxels.front()), expected[voxels.front()]);
        largest = std::max(largest, *std::max_element(expected.begin(), expected.end()));
      }
    }
  }
  EXPECT_GT(largest, 100u);  // components span many runs and rows
}

TEST(LevelMasks, DiagonalNeighboursAcrossWords)
{
  // Pairs of voxels touching only diagonally, across the boundaries of the 64-voxel words of a
  // row: (63, 0)-(64, 1), (128, 0)-(127, 1), and (191, 1)-(192, 0) two headings apart in theta.
  const GridSpec spec = test::smallSpec(200, 2, 3);
  std::vector<std::uint8_t> count(spec.voxelCount(), 0);
  const std::vector<std::size_t> voxels{ spec.index(63, 0, 0),  spec.index(64, 1, 0),  spec.index(128, 0, 1),
                                         spec.index(127, 1, 1), spec.index(191, 1, 0), spec.index(192, 0, 2) };
  for (std::size_t v : voxels)
  {
    count[v] = 4;
  }
  EXPECT_EQ(componentSizes(spec, count, 3, voxels), std::vector<std::size_t>(voxels.size(), 2u));
  EXPECT_THROW(LevelMasks(spec, std::vector<std::uint8_t>(3, 4), 3), std::invalid_argument);  // not this grid's
  const std::vector<std::size_t> brute = bruteSizes(spec, count, 3);
  for (std::size_t v : voxels)
  {
    // From each end alone: the flood crosses the word boundary upwards and downwards.
    EXPECT_EQ(componentSize(spec, count, 3, v), 2u) << "voxel " << v;
    EXPECT_EQ(brute[v], 2u) << "voxel " << v;
  }
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
