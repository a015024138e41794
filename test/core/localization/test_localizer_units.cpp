// Unit tests of the localizer's shared parts, each against an independent brute force:
// components, maximal hypotheses, input validation and candidate ranking. The voxel engine's
// parts are in voxel/test_voxel_units.cpp.
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/count_scan.h"
#include "fdml_localization/core/localization/hypothesis_seeds.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "localizer_test_utils.h"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>
#include <set>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::smallSpec;

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

/// Six readings' voxel sets, each a union of six random 5 x 5 x 3 blobs (periodic in theta).
std::vector<VoxelSet> randomBlobSets(const GridSpec& spec, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
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
  return sets;
}

/// The voxels at @p level that no neighbour strictly extends (brute force over masks).
std::set<std::size_t> undominatedVoxels(const GridSpec& spec, const std::vector<std::size_t>& voxels,
                                        const std::function<unsigned(std::size_t)>& maskOf)
{
  std::set<std::size_t> expected;
  for (std::size_t v : voxels)
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
  return expected;
}

// The buckets skip eight voxels at a time (a word test of its bytes): against a plain scan, at
// every level, on fields of every byte value and of runs reaching a level in one byte only.
TEST(Components, VoxelBucketsMatchAPlainScan)
{
  std::mt19937 rng(11);
  std::vector<std::uint8_t> count(1003, 0);
  for (int round = 0; round < 4; ++round)
  {
    for (std::size_t v = 0; v < count.size(); ++v)
    {
      // Round 0: any byte; then mostly zeros, a rare byte of any value (one byte of a word reaching a level).
      const unsigned value = rng() % 256u;
      count[v] = static_cast<std::uint8_t>(round == 0 || rng() % 16u == 0 ? value : 0u);
    }
    for (int lo : { 1, 2, 7, 127, 128, 129, 200, 255 })
    {
      const int hi = std::min(255, lo + 40);
      const auto buckets = voxelsByCount(count, lo, hi);
      ASSERT_EQ(buckets.size(), static_cast<std::size_t>(hi) + 1);
      for (int c = 0; c <= hi; ++c)
      {
        std::vector<std::size_t> expected;
        for (std::size_t v = 0; v < count.size() && c >= lo; ++v)
        {
          if (count[v] == c)
          {
            expected.push_back(v);
          }
        }
        ASSERT_EQ(buckets[c], expected) << "lo " << lo << " count " << c;
      }
    }
  }
}

// The word tests of eight counts against a byte-by-byte check, on random words and on words
// holding one value among zeros and 255s.
TEST(Components, WordTestsOfEightCountsMatchEachByte)
{
  std::mt19937_64 rng(13);
  for (int trial = 0; trial < 4000; ++trial)
  {
    std::uint64_t word = rng();
    if (trial % 2 == 1)
    {
      word &= 0xff00ff00ff00ff00ull;  // zeros among random bytes
    }
    const unsigned value = static_cast<unsigned>(rng() % 256u);
    const unsigned lo = 1u + static_cast<unsigned>(rng() % 128u);
    bool equal = false;
    bool at_least = false;
    unsigned mask = 0;
    for (int b = 0; b < 8; ++b)
    {
      const unsigned byte = static_cast<unsigned>((word >> (8 * b)) & 0xffu);
      equal = equal || byte == value;
      at_least = at_least || byte >= lo;
      mask |= (byte >= lo ? 1u : 0u) << b;
    }
    ASSERT_EQ(anyByteEqual(word, value), equal) << std::hex << word << " " << value;
    ASSERT_EQ(anyByteAtLeast(word, lo), at_least) << std::hex << word << " " << lo;
    ASSERT_EQ(bytesAtLeast(word, lo), mask) << std::hex << word << " " << lo;
  }
  EXPECT_TRUE(anyByteEqual(0xff00000000000000ull, 255u));
  EXPECT_FALSE(anyByteEqual(0xffffffffffffff01ull, 0u));
  EXPECT_TRUE(anyByteEqual(0x0100000000000000ull, 1u));
  // A byte of 255 next to one just below the level: no carry reaches it.
  EXPECT_EQ(bytesAtLeast(0x7fff7fff7fff7fffull, 128u), 0x55u);
  EXPECT_EQ(bytesAtLeast(0x0000000000000001ull, 1u), 0x01u);
}

TEST(HypothesisSeeds, MaximalSetsMatchBruteForce)
{
  // Random blobs of 6 readings on a small periodic grid; the kept voxels must be exactly those
  // no neighbour strictly extends, grouped into connected plateaus of identical membership.
  const GridSpec spec = smallSpec(12, 10, 8);
  const std::vector<VoxelSet> sets = randomBlobSets(spec, 5);
  const std::function<unsigned(std::size_t)> maskOf = [&](std::size_t v) {
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
    const std::set<std::size_t> expected = undominatedVoxels(spec, buckets[level], maskOf);
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
}

TEST(LocalizerInput, BadOptionsAreAClearError)
{
  const auto map = test::lRoomMap();
  LocalizerOptions options;
  options.engine = Engine::Voxel;
  options.resolution = 24;
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
  // Auto: the adaptive engine's range with the robust method, the voxel engine's with the paper's.
  LocalizerOptions automatic;
  automatic.resolution = 5000;
  EXPECT_EQ(resolveEngine(automatic), Engine::Adaptive);
  EXPECT_TRUE(validate(automatic).empty());
  automatic.method = Method::Paper;
  automatic.min_inliers = 5;
  EXPECT_EQ(resolveEngine(automatic), Engine::Voxel);
  ASSERT_EQ(validate(automatic).size(), 1u);
  EXPECT_NE(validate(automatic)[0].find("for engine voxel"), std::string::npos) << validate(automatic)[0];
  automatic.resolution = 24;
  EXPECT_EQ(Localizer(map, automatic).options().engine, Engine::Voxel);  // resolved when built
  EXPECT_EQ(parseEngine("auto"), Engine::Auto);
  EXPECT_STREQ(toString(Engine::Auto), "auto");
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
