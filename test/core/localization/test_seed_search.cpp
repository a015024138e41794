// The one robust search (seed_search.h) and the one ranking (ranking.h) serve both engines: the
// same inputs give the same answer from either engine wherever both find the truth.
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/seed_refiner.h"
#include "fdml_localization/core/localization/seed_search.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::angleError;
using test::positionError;

Result solve(Engine engine, const std::shared_ptr<const MapRayCaster>& map, const std::vector<Reading>& readings)
{
  LocalizerOptions options;
  options.engine = engine;
  options.resolution = 64;
  options.threads = 1;
  Localizer localizer(map, options);
  return localizer.localize(readings);
}

/// A seed source that supplies one given seed at one level.
class OneSeed : public SeedSource
{
public:
  OneSeed(SearchSeed seed, int level) : seed_(std::move(seed)), level_(level)
  {}
  std::vector<SearchSeed> seedsAt(int level) override
  {
    ++calls_;
    return level == level_ ? std::vector<SearchSeed>{ seed_ } : std::vector<SearchSeed>{};
  }
  int calls() const
  {
    return calls_;
  }

private:
  SearchSeed seed_;
  int level_;
  int calls_ = 0;
};
}  // namespace

TEST(SeedSearch, BothEnginesGiveTheSameAnswerWhereBothFindTheTruth)
{
  const auto map = test::lRoomMap();
  std::mt19937_64 rng(41);
  int both = 0;
  const int trials = 60;
  for (int trial = 0; trial < trials; ++trial)
  {
    const Pose2 truth = test::randomFreePose(*map, rng);
    const std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(10));
    const Result voxel = solve(Engine::Voxel, map, readings);
    const Result adaptive = solve(Engine::Adaptive, map, readings);
    ASSERT_FALSE(voxel.candidates.empty());
    ASSERT_FALSE(adaptive.candidates.empty());
    const Candidate& a = voxel.candidates.front();
    const Candidate& b = adaptive.candidates.front();
    if (positionError(a.pose, truth) > 0.005 || positionError(b.pose, truth) > 0.005)
    {
      continue;
    }
    ++both;
    EXPECT_LT(positionError(a.pose, b.pose), 1e-3) << "trial " << trial;
    EXPECT_LT(angleError(a.pose, b.pose), 1e-3) << "trial " << trial;
    EXPECT_EQ(a.inliers, b.inliers) << "trial " << trial;
    EXPECT_EQ(voxel.min_inliers_used, adaptive.min_inliers_used) << "trial " << trial;
    EXPECT_EQ(isUnambiguous(voxel), isUnambiguous(adaptive)) << "trial " << trial;
  }
  // Both engines find the truth with exact readings almost always.
  EXPECT_GE(both, trials - 2);
}

TEST(SeedSearch, AutomaticKPrimeIsTheConsensusTheSeedReaches)
{
  const auto map = test::lRoomMap();
  const Pose2 truth(3.0, 1.0, 0.4);
  const std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(8));
  SearchSeed seed;
  seed.start = Pose2(truth.x + 0.03, truth.y - 0.02, truth.theta + 0.01);
  seed.hypothesis.assign(readings.size(), true);
  seed.promised = 8;
  seed.support = 7.0;
  seed.region = 42;
  OneSeed source(seed, 8);
  LocalizerOptions options;
  StageTimes times;
  const SeedSearchOutcome found = robustSearch(source, *map, readings, options, SeedScale{ 0.1, 0.1 }, times);
  ASSERT_EQ(found.candidates.size(), 1u);
  EXPECT_EQ(found.min_inliers_used, 8);
  EXPECT_EQ(found.regions, std::vector<std::size_t>{ 42 });
  EXPECT_EQ(found.candidates[0].support, 7.0);
  EXPECT_LT(positionError(found.candidates[0].pose, truth), 1e-3);
  // Reached at the first level asked: no lower level was requested.
  EXPECT_EQ(source.calls(), 1);
}

TEST(SeedSearch, TheEnumerationOfARegionStopsAtTheDeadline)
{
  const auto map = test::lRoomMap();
  const Pose2 truth(3.0, 1.0, 0.4);
  const std::vector<Reading> readings = test::exactReadings(*map, truth, test::inPlaceOffsets(8));
  std::vector<Pose2> region;  // a lattice of 125 poses around the truth: 2 cm, 1 deg
  for (int i = -2; i <= 2; ++i)
  {
    for (int j = -2; j <= 2; ++j)
    {
      for (int t = -2; t <= 2; ++t)
      {
        region.emplace_back(truth.x + 0.02 * i, truth.y + 0.02 * j, truth.theta + 0.0175 * t);
      }
    }
  }
  const std::vector<bool> hypothesis(readings.size(), true);
  const std::vector<Pose2> none;
  const Pose2 start(truth.x + 0.05, truth.y, truth.theta);
  Refiner unbounded(*map, start, readings, hypothesis, RefinementSettings(), none);
  unbounded.enumerate(region, 0.3, 0.01, Deadline());
  const std::vector<Candidate> reached = unbounded.ties();
  ASSERT_FALSE(reached.empty());
  EXPECT_LT(positionError(reached.front().pose, truth), 1e-3);
  const Deadline spent(1e-6);
  while (!spent.passed())
  {
    // the budget is spent before the enumeration starts
  }
  Refiner bounded(*map, start, readings, hypothesis, RefinementSettings(), none);
  bounded.enumerate(region, 0.3, 0.01, spent);
  EXPECT_TRUE(bounded.ties().empty());
}

TEST(Ranking, UnambiguousOnlyWithAStrictlyLargerNetConsensus)
{
  Result result;
  EXPECT_FALSE(isUnambiguous(result));
  Candidate a;
  a.inliers = 8;
  result.candidates = { a };
  EXPECT_TRUE(isUnambiguous(result));
  Candidate b = a;
  b.contradicted = 1;  // 8 inliers, one reading through a wall: net 7
  result.candidates = { a, b };
  EXPECT_TRUE(isUnambiguous(result));
  b.contradicted = 0;
  result.candidates = { a, b };
  EXPECT_FALSE(isUnambiguous(result));
  // The order: net consensus first, then fewer contradicted, then rms.
  Candidate c = a;
  c.inliers = 9;
  c.contradicted = 1;
  Candidate d = a;
  d.rms_residual = 0.01;
  EXPECT_TRUE(betterCandidate(a, c));
  EXPECT_TRUE(betterCandidate(a, d));
  EXPECT_FALSE(betterCandidate(d, a));
}

}  // namespace core
}  // namespace fdml_localization
