// Unit tests of the voxel engine's parts, each against an independent brute force: grid,
// dilation, distance table blocks, counting vs subset enumeration, and the table cache.
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::smallSpec;
using test::tempDir;

TEST(VoxelGrid, FromMapUsesSquareCellsAndAMargin)
{
  const auto map = test::lRoomMap();
  const GridSpec spec = GridSpec::fromMap(map->map(), 64, 0);
  EXPECT_DOUBLE_EQ(spec.cell, 8.0 / 64);
  EXPECT_EQ(spec.nx, 66);
  EXPECT_EQ(spec.ny, 50);
  EXPECT_EQ(spec.nt, 64);
  EXPECT_LT(spec.origin_x, 0.0);
  EXPECT_GT(spec.origin_x + spec.nx * spec.cell, 8.0);
  EXPECT_THROW(GridSpec::fromMap(map->map(), 15, 0), std::invalid_argument);
  EXPECT_THROW(GridSpec::fromMap(map->map(), 1025, 0), std::invalid_argument);
  EXPECT_THROW(GridSpec::fromMap(PolygonMap(), 64, 0), std::invalid_argument);
  for (std::size_t v : { std::size_t(0), std::size_t(12345), spec.voxelCount() - 1 })
  {
    int ix = 0;
    int iy = 0;
    int it = 0;
    ASSERT_TRUE(spec.locate(spec.centre(v), ix, iy, it));
    EXPECT_EQ(spec.index(ix, iy, it), v);
  }
}

/// @p dilated is @p set dilated by one voxel (brute force over each voxel's neighbours).
void expectDilationOf(const GridSpec& spec, const VoxelSet& set, const VoxelSet& dilated)
{
  for (int it = 0; it < spec.nt; ++it)
  {
    for (int iy = 0; iy < spec.ny; ++iy)
    {
      for (int ix = 0; ix < spec.nx; ++ix)
      {
        bool expected = set.test(ix, iy, it);
        forEachNeighbour(spec, ix, iy, it, [&](std::size_t u) {
          int x = 0;
          int y = 0;
          int t = 0;
          spec.unindex(u, x, y, t);
          expected = expected || set.test(x, y, t);
        });
        ASSERT_EQ(dilated.test(ix, iy, it), expected) << ix << " " << iy << " " << it << " of nt " << spec.nt;
      }
    }
  }
}

TEST(VoxelGrid, DilationMatchesBruteForce)
{
  // Rows crossing a word boundary; one, two, three and six headings (the periodic neighbours
  // coincide on the smaller grids).
  for (const int nt : { 6, 1, 2, 3 })
  {
    const GridSpec spec = smallSpec(70, 5, nt);
    std::mt19937_64 rng(3 + nt);
    VoxelSet set(spec);
    for (int i = 0; i < 25; ++i)
    {
      set.set(static_cast<int>(rng() % 70), static_cast<int>(rng() % 5), static_cast<int>(rng() % nt));
    }
    set.set(63, 0, 0);
    set.set(69, 4, nt - 1);
    const VoxelSet dilated = set.dilated();
    expectDilationOf(spec, set, dilated);
    // Padding bits stay clear.
    EXPECT_EQ(dilated.row(0, 0)[1] >> 6, 0u);
    // Into a set of the same shape holding other bits (every word is written), and into itself.
    VoxelSet reused(spec);
    for (std::uint64_t& w : reused.words())
    {
      w = ~std::uint64_t{ 0 };
    }
    set.dilateInto(reused);
    EXPECT_TRUE(reused == dilated) << "nt " << nt;
    VoxelSet self = set;
    self.dilateInto(self);
    EXPECT_TRUE(self == dilated) << "nt " << nt;
  }
}

TEST(VoxelGrid, SlicesClearAndReshapeKeepsTheShape)
{
  const GridSpec spec = smallSpec(70, 5, 4);
  VoxelSet set;
  set.reshape(spec);
  set.clear();
  set.set(3, 2, 1);
  set.set(68, 4, 2);
  set.clearSlice(1);
  EXPECT_FALSE(set.test(3, 2, 1));
  EXPECT_TRUE(set.test(68, 4, 2));
  EXPECT_EQ(set.count(), 1u);
  EXPECT_TRUE(set == [&] {
    VoxelSet expected(spec);
    expected.set(68, 4, 2);
    return expected;
  }());
}

TEST(DistanceTable, SamplesAndBlocksMatchBruteForce)
{
  const auto map = test::lRoomMap();
  const GridSpec spec = GridSpec::fromMap(map->map(), 24, 20);
  const DistanceTable table = DistanceTable::build(*map, spec, 2);
  std::mt19937_64 rng(1);
  for (int trial = 0; trial < 2000; ++trial)
  {
    const int ix = static_cast<int>(rng() % spec.nx);
    const int iy = static_cast<int>(rng() % spec.ny);
    const int it = static_cast<int>(rng() % spec.nt);
    const Pose2 centre = spec.centre(spec.index(ix, iy, it));
    const float value = table.at(ix, iy, it);
    if (map->isFree(centre.position()))
    {
      EXPECT_FLOAT_EQ(value, static_cast<float>(map->range(centre)));
    }
    else
    {
      EXPECT_TRUE(std::isnan(value));
    }
    float lo = std::numeric_limits<float>::infinity();
    float hi = -lo;
    if (ix + 1 < spec.nx && iy + 1 < spec.ny)
    {
      for (int dt = 0; dt < 2; ++dt)
      {
        for (int dy = 0; dy < 2; ++dy)
        {
          for (int dx = 0; dx < 2; ++dx)
          {
            const float h = table.at(ix + dx, iy + dy, (it + dt) % spec.nt);
            if (!std::isnan(h))
            {
              lo = std::min(lo, h);
              hi = std::max(hi, h);
            }
          }
        }
      }
    }
    const std::size_t v = spec.index(ix, iy, it);
    EXPECT_EQ(table.blockMin()[v], table.steps().down(lo));
    EXPECT_EQ(table.blockMax()[v], table.steps().up(hi));
  }
}

// The count is added bit-sliced: against a voxel-by-voxel sum, for 1 to 255 random sets on a
// grid whose rows end inside a word.
TEST(VoxelEngine, CountFieldIsThePerVoxelSumOfTheSets)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 70;
  options.theta_resolution = 16;
  VoxelEngine engine(map, options);
  const GridSpec& spec = engine.grid();
  ASSERT_NE(spec.nx % 64, 0);
  std::mt19937_64 rng(21);
  // One field written over and over (stale counts must not survive), the last sets sparse (words
  // no set holds).
  std::vector<std::uint8_t> count;
  for (const auto& [n, density] : { std::make_pair(1, 0.4), std::make_pair(3, 0.4), std::make_pair(10, 0.4),
                                    std::make_pair(31, 0.4), std::make_pair(255, 1.0), std::make_pair(4, 0.002) })
  {
    std::vector<VoxelSet> sets(static_cast<std::size_t>(n), VoxelSet(spec));
    std::bernoulli_distribution in(density);
    for (VoxelSet& set : sets)
    {
      for (std::size_t v = 0; v < spec.voxelCount(); ++v)
      {
        int ix = 0, iy = 0, it = 0;
        spec.unindex(v, ix, iy, it);
        if (in(rng))
        {
          set.set(ix, iy, it);
        }
      }
    }
    engine.countField(sets, count);
    ASSERT_EQ(count.size(), spec.voxelCount());
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      int ix = 0, iy = 0, it = 0;
      spec.unindex(v, ix, iy, it);
      int expected = 0;
      for (const VoxelSet& set : sets)
      {
        expected += set.test(ix, iy, it) ? 1 : 0;
      }
      ASSERT_EQ(count[v], expected) << n << " sets, voxel " << v;
    }
  }
}

TEST(VoxelEngine, CountingEqualsSubsetEnumeration)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 24;
  VoxelEngine engine(map, options);
  const int k = 8;
  const int kp = 5;
  std::mt19937_64 rng(9);
  const Pose2 truth = test::randomFreePose(*map, rng);
  std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(k));
  readings[1].range *= 0.5;  // two obstacle hits
  readings[6].range *= 0.7;
  const std::vector<VoxelSet> sets = engine.preimages(readings);
  std::vector<std::uint8_t> count;
  engine.countField(sets, count);

  VoxelSet by_enumeration(engine.grid());
  int subsets = 0;
  for (unsigned mask = 0; mask < (1u << k); ++mask)
  {
    if (__builtin_popcount(mask) != kp)
    {
      continue;
    }
    ++subsets;
    VoxelSet intersection = sets[__builtin_ctz(mask)];
    for (int i = 0; i < k; ++i)
    {
      if (mask & (1u << i))
      {
        intersection &= sets[i];
      }
    }
    by_enumeration |= intersection;
  }
  ASSERT_EQ(subsets, 56);
  VoxelSet by_count(engine.grid());
  const GridSpec& spec = engine.grid();
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    int ix = 0;
    int iy = 0;
    int it = 0;
    spec.unindex(v, ix, iy, it);
    if (count[v] >= kp)
    {
      by_count.set(ix, iy, it);
    }
    int members = 0;
    for (const VoxelSet& s : sets)
    {
      members += s.test(ix, iy, it) ? 1 : 0;
    }
    ASSERT_EQ(count[v], members);
  }
  EXPECT_GT(by_count.count(), 0u);
  EXPECT_TRUE(by_count == by_enumeration);
}

TEST(TableCache, RoundTripAndEveryKindOfDamageIsRejected)
{
  const auto map = test::lRoomMap();
  const GridSpec spec = GridSpec::fromMap(map->map(), 20, 16);
  const DistanceTable table = DistanceTable::build(*map, spec, 1);
  const std::string dir = tempDir("cache");
  const std::uint64_t hash = map->map().hash();
  const std::string path = tableCachePath(dir, hash, spec);
  ASSERT_TRUE(saveTable(path, hash, table));
  DistanceTable loaded;
  std::string why;
  ASSERT_TRUE(loadTable(path, hash, spec, loaded, &why)) << why;
  ASSERT_EQ(loaded.values().size(), table.values().size());
  EXPECT_EQ(0, std::memcmp(loaded.values().data(), table.values().data(), table.values().size() * sizeof(float)));

  EXPECT_FALSE(loadTable(path, hash + 1, spec, loaded, &why));
  GridSpec other = spec;
  other.nt += 1;
  EXPECT_FALSE(loadTable(path, hash, other, loaded, &why));

  const auto size = std::filesystem::file_size(path);
  // A flipped byte in the data.
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size / 2));
    char c = 0;
    f.read(&c, 1);
    f.seekp(static_cast<std::streamoff>(size / 2));
    c = static_cast<char>(c ^ 0x10);
    f.write(&c, 1);
  }
  EXPECT_FALSE(loadTable(path, hash, spec, loaded, &why));
  EXPECT_NE(why.find("checksum"), std::string::npos) << why;
  // Truncated.
  ASSERT_TRUE(saveTable(path, hash, table));
  std::filesystem::resize_file(path, size - 100);
  EXPECT_FALSE(loadTable(path, hash, spec, loaded, &why));
  EXPECT_NE(why.find("truncated"), std::string::npos) << why;
  // Garbage.
  {
    std::ofstream f(path, std::ios::binary | std::ios::trunc);
    f << "not a table";
  }
  EXPECT_FALSE(loadTable(path, hash, spec, loaded, &why));
  // No temporary files are left behind.
  int files = 0;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
  {
    (void)entry;
    ++files;
  }
  EXPECT_EQ(files, 1);
  std::filesystem::remove_all(dir);
}

TEST(TableCache, CorruptCacheIsRebuiltAndGivesIdenticalResults)
{
  const auto map = test::lRoomMap();
  const std::string dir = tempDir("rebuild");
  LocalizerOptions options;
  options.resolution = 40;
  options.cache_dir = dir;
  const Pose2 truth(6.2, 3.1, 0.7);
  const std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(10));

  auto run = [&](TableSource expected_source) {
    VoxelEngine engine(map, options);
    engine.prepare();
    EXPECT_EQ(engine.tableSource(), expected_source) << engine.cacheMessage();
    return engine.localize(readings);
  };
  const Result first = run(TableSource::BuiltAndSaved);
  const Result loaded = run(TableSource::Loaded);
  const std::string path = tableCachePath(dir, map->map().hash(), GridSpec::fromMap(map->map(), 40, 0));
  std::filesystem::resize_file(path, std::filesystem::file_size(path) / 3);
  const Result rebuilt = run(TableSource::Rebuilt);
  const Result reloaded = run(TableSource::Loaded);
  for (const Result* r : { &loaded, &rebuilt, &reloaded })
  {
    ASSERT_EQ(r->candidates.size(), first.candidates.size());
    for (std::size_t i = 0; i < first.candidates.size(); ++i)
    {
      EXPECT_EQ(r->candidates[i].pose.x, first.candidates[i].pose.x);
      EXPECT_EQ(r->candidates[i].pose.y, first.candidates[i].pose.y);
      EXPECT_EQ(r->candidates[i].pose.theta, first.candidates[i].pose.theta);
      EXPECT_EQ(r->candidates[i].inlier_mask, first.candidates[i].inlier_mask);
    }
  }
  ASSERT_FALSE(first.candidates.empty());
  EXPECT_LT(test::positionError(first.candidates[0].pose, truth), 1e-3);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
