// Unit tests of the voxel localizer's parts, each against an independent brute force:
// grid, dilation, distance table blocks, preimages, counting vs subset enumeration,
// components, the table cache, input validation and candidate ranking.
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/hypothesis_seeds.h"
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <unistd.h>

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
GridSpec smallSpec(int nx, int ny, int nt)
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

std::string tempDir(const std::string& name)
{
  const auto dir =
      std::filesystem::temp_directory_path() / ("fdml_localizer_test_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  return dir.string();
}

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

TEST(VoxelGrid, DilationMatchesBruteForce)
{
  const GridSpec spec = smallSpec(70, 5, 6);  // rows cross a word boundary
  std::mt19937_64 rng(3);
  VoxelSet set(spec);
  for (int i = 0; i < 25; ++i)
  {
    set.set(static_cast<int>(rng() % 70), static_cast<int>(rng() % 5), static_cast<int>(rng() % 6));
  }
  set.set(63, 0, 0);
  set.set(69, 4, 5);
  const VoxelSet dilated = set.dilated();
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
        ASSERT_EQ(dilated.test(ix, iy, it), expected) << ix << " " << iy << " " << it;
      }
    }
  }
  // Padding bits stay clear.
  EXPECT_EQ(dilated.row(0, 0)[1] >> 6, 0u);
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
    EXPECT_EQ(table.blockMin()[v], lo);
    EXPECT_EQ(table.blockMax()[v], hi);
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

TEST(Components, PeriodicInThetaWithCircularMean)
{
  const GridSpec spec = smallSpec(10, 10, 16);
  std::vector<std::uint8_t> count(spec.voxelCount(), 0);
  // One blob straddling theta = +-pi: cells 15 and 0 (and 14, 1).
  for (int it : { 14, 15, 0, 1 })
  {
    count[spec.index(4, 4, it)] = 5;
  }
  count[spec.index(8, 8, 7)] = 5;  // a separate one
  const std::vector<VoxelCluster> clusters = connectedComponents(spec, count, 5);
  ASSERT_EQ(clusters.size(), 2u);
  const VoxelCluster& blob = clusters[0].voxels.size() == 4 ? clusters[0] : clusters[1];
  ASSERT_EQ(blob.voxels.size(), 4u);
  EXPECT_NEAR(std::abs(blob.centroid.theta), kPi, 1e-9);
  EXPECT_NEAR(blob.centroid.x, spec.centreX(4), 1e-12);
}

TEST(Components, EveryCountPeakBecomesItsOwnSeed)
{
  const GridSpec spec = smallSpec(20, 5, 16);
  std::vector<std::uint8_t> count(spec.voxelCount(), 0);
  // A ridge at count 4 joining two peaks of count 6 and 5.
  for (int ix = 2; ix <= 16; ++ix)
  {
    count[spec.index(ix, 2, 3)] = 4;
  }
  count[spec.index(3, 2, 3)] = 6;
  count[spec.index(15, 2, 3)] = 5;
  ASSERT_EQ(connectedComponents(spec, count, 4).size(), 1u);
  const auto buckets = voxelsByCount(count, 3, 8);
  const auto at6 = regionalMaxima(spec, count, 6, buckets[6]);
  const auto at5 = regionalMaxima(spec, count, 5, buckets[5]);
  const auto at4 = regionalMaxima(spec, count, 4, buckets[4]);
  ASSERT_EQ(at6.size(), 1u);
  ASSERT_EQ(at5.size(), 1u);
  EXPECT_EQ(at4.size(), 0u);  // the ridge is no peak
  EXPECT_NEAR(at6[0].centroid.x, spec.centreX(3), 1e-12);
  EXPECT_NEAR(at5[0].centroid.x, spec.centreX(15), 1e-12);
  EXPECT_EQ(componentSize(spec, count, 4, spec.index(3, 2, 3)), 15u);
}

TEST(HypothesisSeeds, MaximalSetsMatchBruteForce)
{
  // Random blobs of 6 readings on a small periodic grid; the kept voxels must be exactly those
  // no neighbour strictly extends, grouped into connected plateaus of identical membership.
  const GridSpec spec = smallSpec(12, 10, 8);
  std::mt19937_64 rng(5);
  std::vector<VoxelSet> sets(6, VoxelSet(spec));
  std::uniform_int_distribution<int> ux(0, spec.nx - 1);
  std::uniform_int_distribution<int> uy(0, spec.ny - 1);
  std::uniform_int_distribution<int> ut(0, spec.nt - 1);
  for (VoxelSet& set : sets)
  {
    for (int blob = 0; blob < 6; ++blob)
    {
      const int cx = ux(rng);
      const int cy = uy(rng);
      const int ct = ut(rng);
      for (int dt = -1; dt <= 1; ++dt)
      {
        for (int dy = -2; dy <= 2; ++dy)
        {
          for (int dx = -2; dx <= 2; ++dx)
          {
            const int x = cx + dx;
            const int y = cy + dy;
            if (x >= 0 && x < spec.nx && y >= 0 && y < spec.ny)
            {
              set.set(x, y, (ct + dt + spec.nt) % spec.nt);
            }
          }
        }
      }
    }
  }
  auto maskOf = [&](std::size_t v) {
    int ix = 0;
    int iy = 0;
    int it = 0;
    spec.unindex(v, ix, iy, it);
    unsigned mask = 0;
    for (std::size_t i = 0; i < sets.size(); ++i)
    {
      mask |= sets[i].test(ix, iy, it) ? 1u << i : 0u;
    }
    return mask;
  };
  std::vector<std::uint8_t> count(spec.voxelCount(), 0);
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    count[v] = static_cast<std::uint8_t>(__builtin_popcount(maskOf(v)));
  }
  const auto buckets = voxelsByCount(count, 2, 6);
  int plateaus = 0;
  for (int level = 2; level <= 6; ++level)
  {
    std::set<std::size_t> expected;
    for (std::size_t v : buckets[level])
    {
      int ix = 0;
      int iy = 0;
      int it = 0;
      spec.unindex(v, ix, iy, it);
      bool dominated = false;
      forEachNeighbour(spec, ix, iy, it, [&](std::size_t u) {
        dominated = dominated || ((maskOf(u) & maskOf(v)) == maskOf(v) && maskOf(u) != maskOf(v));
      });
      if (!dominated)
      {
        expected.insert(v);
      }
    }
    std::set<std::size_t> kept;
    for (const HypothesisSeed& seed : maximalHypotheses(spec, sets, count, level, buckets[level], 2))
    {
      ++plateaus;
      EXPECT_EQ(seed.plateau.peak_count, level);
      const unsigned mask = maskOf(seed.plateau.voxels.front());
      for (std::size_t i = 0; i < sets.size(); ++i)
      {
        EXPECT_EQ(seed.hypothesis[i], ((mask >> i) & 1u) == 1u);
      }
      for (std::size_t v : seed.plateau.voxels)
      {
        EXPECT_EQ(maskOf(v), mask);
        EXPECT_TRUE(kept.insert(v).second) << "voxel in two plateaus";
      }
      // Connected: the plateau is one component of its own voxels.
      std::vector<std::uint8_t> own(spec.voxelCount(), 0);
      for (std::size_t v : seed.plateau.voxels)
      {
        own[v] = 1;
      }
      EXPECT_EQ(connectedComponents(spec, own, 1).size(), 1u);
    }
    EXPECT_EQ(kept, expected) << "level " << level;
  }
  EXPECT_GT(plateaus, 10);
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

TEST(LocalizerInput, BadInputIsAClearError)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.resolution = 24;
  Localizer localizer(map, options);
  const std::vector<Reading> good = test::exactReadings(*map, Pose2(1, 1, 0), test::inPlaceOffsets(5));
  auto expectError = [&](std::vector<Reading> readings, const std::string& needle) {
    try
    {
      localizer.localize(readings);
      ADD_FAILURE() << "no error for " << needle;
    }
    catch (const InvalidInput& e)
    {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  auto with = [&](int i, double range) {
    std::vector<Reading> r = good;
    r[i].range = range;
    return r;
  };
  expectError(with(2, std::nan("")), "reading 2: range is NaN");
  expectError(with(3, -0.5), "reading 3: negative range");
  expectError(with(1, kInf), "needs a finite max_range");
  expectError(std::vector<Reading>(good.begin(), good.begin() + 2), "at least 3 readings");
  expectError({}, "at least 3 readings");
  std::vector<Reading> beyond = good;
  beyond[0].max_range = 0.5;
  beyond[0].range = 0.8;
  expectError(beyond, "exceeds max_range");
  std::vector<Reading> bad_offset = good;
  bad_offset[4].offset.x = kInf;
  expectError(bad_offset, "reading 4: offset");

  LocalizerOptions too_many = options;
  too_many.min_inliers = 6;
  Localizer strict(map, too_many);
  EXPECT_THROW(strict.localize(good), InvalidInput);

  for (int n : { 15, 1025, 0, -3 })
  {
    LocalizerOptions o = options;
    o.resolution = n;
    EXPECT_THROW(Localizer(map, o), std::invalid_argument) << n;
    EXPECT_FALSE(validate(o).empty());
  }
  LocalizerOptions many = options;
  many.resolution = 2000;
  many.agreement_tolerance = -1.0;
  many.max_candidates = 0;
  EXPECT_EQ(validate(many).size(), 3u);
  LocalizerOptions paper = options;
  paper.method = Method::Paper;
  EXPECT_THROW(Localizer(map, paper), std::invalid_argument);
  // The resolution's range depends on the engine: the adaptive engine goes far finer.
  LocalizerOptions adaptive = options;
  adaptive.engine = Engine::Adaptive;
  EXPECT_NO_THROW(Localizer(map, adaptive));
  adaptive.resolution = 5000;  // fine for the adaptive engine, too many voxels for the voxel one
  EXPECT_TRUE(validate(adaptive).empty());
  adaptive.resolution = 200000;
  EXPECT_EQ(validate(adaptive).size(), 1u);
  EXPECT_THROW(Localizer(std::make_shared<const MapRayCaster>(), options), std::invalid_argument);
  EXPECT_TRUE(validate(LocalizerOptions()).empty());
}

TEST(LocalizerInput, ParseAndPrintNames)
{
  for (Method m : { Method::Robust, Method::Paper, Method::Baseline })
  {
    EXPECT_EQ(parseMethod(toString(m)), m);
  }
  for (Engine e : { Engine::Voxel, Engine::Adaptive })
  {
    EXPECT_EQ(parseEngine(toString(e)), e);
  }
  EXPECT_THROW(parseMethod("Robust"), std::invalid_argument);
  EXPECT_THROW(parseEngine(""), std::invalid_argument);
}

TEST(CandidateRefinement, PolishConvergesAndRankingDropsDuplicates)
{
  const auto map = test::lRoomMap();
  const Pose2 truth(3.3, 1.2, -2.0);
  const std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(8));
  const std::vector<bool> all(readings.size(), true);
  const PolishOutcome p = polishPose(*map, Pose2(3.34, 1.17, -1.97), readings, all, 0.0, 30, 0.01);
  EXPECT_LT(test::positionError(p.pose, truth), 1e-7);
  EXPECT_LT(test::angleError(p.pose, truth), 1e-7);
  EXPECT_GT(p.covariance(0, 0), 0.0);
  const PoseEvaluation eval = evaluatePose(*map, p.pose, readings, 0.01);
  EXPECT_EQ(eval.inliers, 8);

  std::vector<Candidate> cands(4);
  cands[0].pose = Pose2(1, 1, 0);
  cands[0].inliers = 6;
  cands[0].rms_residual = 0.01;
  cands[1].pose = Pose2(1.05, 1, 0.02);  // duplicate of 2, worse
  cands[1].inliers = 7;
  cands[1].rms_residual = 0.02;
  cands[2].pose = Pose2(1.0, 1.01, 0.0);
  cands[2].inliers = 7;
  cands[2].rms_residual = 0.001;
  cands[3].pose = Pose2(1.0, 1.0, 3.0);  // same place, other heading
  cands[3].inliers = 5;
  const std::vector<Candidate> ranked = rankAndDeduplicate(cands, 0.1, 0.1, 10);
  ASSERT_EQ(ranked.size(), 2u);
  EXPECT_EQ(ranked[0].rms_residual, 0.001);
  EXPECT_EQ(ranked[1].inliers, 5);
  EXPECT_EQ(rankAndDeduplicate(cands, 0.0, 0.0, 3).size(), 3u);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
