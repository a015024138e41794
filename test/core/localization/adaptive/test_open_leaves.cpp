// Which leaves the region fill searches (open_leaves.h): a candidate holds a leaf back only when
// it reaches the fill's target with an RMS within the noise (twentieth round, verification seeds
// 802 and 805), and one short of exact has it searched first, as its own place (seed 810); the
// leaves agreeing with the target come before the next rank of other regions (seed 820).
#include "fdml_localization/core/localization/adaptive/open_leaves.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr double kNoise = 0.01;  // RefinementSettings::noise_sigma [m]
constexpr std::int64_t kThetaCells = 126;

/// A candidate at @p pose explaining @p inliers readings with @p rms [m] and standard deviations
/// @p sd (x [m], y [m], theta [rad]).
Candidate candidateAt(const Pose2& pose, int inliers, double rms, const Eigen::Vector3d& sd)
{
  Candidate c;
  c.pose = pose;
  c.inliers = inliers;
  c.rms_residual = rms;
  c.covariance = sd.cwiseProduct(sd).asDiagonal();
  return c;
}

/// A 5 cm, 0.05 rad leaf centred on @p q, reaching @p count readings.
LeafBox leafAround(const Pose2& q, int count)
{
  LeafBox leaf;
  leaf.box = PoseBox{ q.x - 0.025, q.x + 0.025, q.y - 0.025, q.y + 0.025, q.theta - 0.025, q.theta + 0.025 };
  leaf.count = count;
  return leaf;
}

struct OpenLeavesTest : ::testing::Test
{
  void SetUp() override
  {
    map = test::loadMap("maps/apartment.poly");
    std::mt19937_64 rng(7);
    q = test::randomFreePose(*map, rng, 0.3);
    std::vector<Pose2> offsets;
    for (int i = 0; i < 6; ++i)
    {
      offsets.emplace_back(0.0, 0.0, -kPi + i * kPi / 3.0);
    }
    readings = test::exactReadings(*map, q, offsets);
    leaves = { leafAround(q, 6) };
  }

  std::vector<OpenLeaf> open(const std::vector<Candidate>& candidates) const
  {
    return openLeaves(*map, leaves, 6, kThetaCells, readings, candidates, LocalizerOptions(), kNoise);
  }

  std::shared_ptr<const MapRayCaster> map;
  Pose2 q;
  std::vector<Reading> readings;
  std::vector<LeafBox> leaves;
};

TEST(AccountsFor, OnlyACandidateReachingTheTargetWithinTheNoise)
{
  const Eigen::Vector3d sd(0.01, 0.01, 0.01);
  EXPECT_TRUE(accountsFor(candidateAt(Pose2(), 6, 0.0, sd), 6, kNoise));
  EXPECT_TRUE(accountsFor(candidateAt(Pose2(), 7, kNoise, sd), 6, kNoise));
  EXPECT_FALSE(accountsFor(candidateAt(Pose2(), 6, 0.025, sd), 6, kNoise));
  EXPECT_FALSE(accountsFor(candidateAt(Pose2(), 5, 0.0, sd), 6, kNoise));
}

TEST_F(OpenLeavesTest, ALeafHoldingACandidateAtTheTargetIsNotOpenButOneShortOfItHoldsNoLeaf)
{
  const Eigen::Vector3d sd(0.005, 0.005, 0.005);
  EXPECT_TRUE(open({ candidateAt(q, 6, 0.0, sd) }).empty());
  const std::vector<OpenLeaf> short_of_it = open({ candidateAt(q, 5, 0.0, sd) });
  ASSERT_EQ(short_of_it.size(), 1u);
  EXPECT_LT(short_of_it.front().rival.inliers, 0);
  EXPECT_EQ(short_of_it.front().centre.inliers, 6);  // the leaf's centre is the truth: verified
}

TEST_F(OpenLeavesTest, AnExactContinuumHoldsTheLeafBackOneShortOfExactSearchesItFirst)
{
  // A candidate 1 m away along x whose continuum (sd 2 m along x) reaches the leaf.
  const Pose2 along(q.x + 1.0, q.y, q.theta);
  const Eigen::Vector3d sd(2.0, 0.005, 0.005);
  const std::vector<OpenLeaf> exact = open({ candidateAt(along, 6, 0.0, sd) });
  ASSERT_EQ(exact.size(), 1u);
  EXPECT_EQ(exact.front().rival.inliers, 6);
  EXPECT_FALSE(exact.front().own);
  EXPECT_LT(exact.front().centre.inliers, 0);  // left to pass 1, verified when searched
  // Short of exact, within the noise: its own place, searched first (verification seed 810).
  const std::vector<OpenLeaf> settled = open({ candidateAt(along, 6, 0.001, sd) });
  ASSERT_EQ(settled.size(), 1u);
  EXPECT_EQ(settled.front().rival.inliers, 6);
  EXPECT_TRUE(settled.front().own);
  EXPECT_EQ(settled.front().centre.inliers, 6);  // verified: the best of its own place first
  const std::vector<OpenLeaf> beyond = open({ candidateAt(along, 6, 0.025, sd) });
  ASSERT_EQ(beyond.size(), 1u);
  EXPECT_EQ(beyond.front().rival.inliers, 6);  // a place there still has to beat it
  EXPECT_FALSE(beyond.front().own);
  EXPECT_EQ(beyond.front().centre.inliers, 6);  // ranked now, searched in pass 0
}

TEST_F(OpenLeavesTest, LeavesAgreeingWithTheTargetComeBeforeTheNextRankOfOtherRegions)
{
  // Region A: three 1 cm leaves in a row at the pose the readings were taken from (each agrees
  // with all 6 readings at its scale); region B: four in a row at another free pose.
  std::mt19937_64 rng(11);
  const Pose2 p = test::randomFreePose(*map, rng, 0.3);
  const auto leafAt = [](const Pose2& c, std::int64_t ix) {
    LeafBox leaf;
    leaf.box = PoseBox{ c.x - 0.005, c.x + 0.005, c.y - 0.005, c.y + 0.005, c.theta - 0.005, c.theta + 0.005 };
    leaf.count = 6;
    leaf.ix = ix;
    return leaf;
  };
  leaves.clear();
  for (int j = 0; j < 3; ++j)
  {
    leaves.push_back(leafAt(Pose2(q.x + 0.01 * j, q.y, q.theta), j));
  }
  for (int j = 0; j < 4; ++j)
  {
    leaves.push_back(leafAt(Pose2(p.x + 0.01 * j, p.y, p.theta), 100 + j));
  }
  const std::vector<OpenLeaf> order = open({});
  ASSERT_EQ(order.size(), 7u);
  const auto inA = [&](const OpenLeaf& o) { return o.leaf->box.x0 < q.x + 0.03 && o.leaf->box.x1 > q.x - 0.01; };
  for (const OpenLeaf& o : order)
  {
    // Preconditions: A's leaves agree with the target at their scale, B's do not.
    ASSERT_EQ(o.agreement.within >= 6, inA(o)) << o.leaf->box.x0 << " " << o.agreement.within;
  }
  // Every region's best first, then A's two others (they agree), then B's three others: round
  // robin by rank alone would take B's second before A's third.
  EXPECT_EQ(order[0].rank + order[1].rank, 0);
  EXPECT_TRUE(inA(order[2]) && inA(order[3]));
  EXPECT_FALSE(inA(order[4]) || inA(order[5]) || inA(order[6]));
}

TEST_F(OpenLeavesTest, ProbesInParallelAreTheSerialLoopsOnAnyNumberOfThreads)
{
  // 600 leaves of 1 m and 0.8 rad around the truth, at the target, and the serial loop: each
  // leaf probed in turn while the budget lasts (the probe overrunning it cut short).
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> near(-0.8, 0.8);
  leaves.clear();
  for (int j = 0; j < 600; ++j)
  {
    LeafBox leaf = leafAround(Pose2(q.x + near(rng), q.y + near(rng), q.theta + near(rng)), 6);
    leaf.box = PoseBox{ leaf.box.x0 - 0.475, leaf.box.x1 + 0.475, leaf.box.y0 - 0.475,
                        leaf.box.y1 + 0.475, leaf.box.t0 - 0.375, leaf.box.t1 + 0.375 };
    leaves.push_back(leaf);
  }
  std::vector<OpenLeaf> start;
  for (const LeafBox& leaf : leaves)
  {
    OpenLeaf o{ &leaf, Candidate(), 0, 0, 6, Candidate(), false, false, BoxAgreement() };
    o.centre = verifiedBox(*map, leaf.box, readings, LocalizerOptions().agreement_tolerance, o.agreement);
    start.push_back(o);
  }
  for (long budget : { 1L, 37L, 400L, 3000L, 1000000L })
  {
    std::vector<OpenLeaf> serial = start;
    long left = budget;
    std::size_t lowered = 0;
    for (OpenLeaf& o : serial)
    {
      if (left <= 0)
      {
        break;
      }
      o.bound -= probeLeaf(*map, o.leaf->box, readings, LocalizerOptions(), 6, 3, o.centre, left) ? 0 : 1;
      lowered += o.bound < 6 ? 1 : 0;
    }
    EXPECT_GT(lowered + (budget < 1000 ? 1 : 0), 0u) << "budget " << budget;
    for (int threads : { 1, 2, 3 })
    {
      LocalizerOptions options;
      options.threads = threads;
      std::vector<OpenLeaf> parallel = start;
      probeOpenLeaves(*map, readings, options, 6, budget, parallel);
      for (std::size_t i = 0; i < parallel.size(); ++i)
      {
        ASSERT_EQ(parallel[i].bound, serial[i].bound) << "budget " << budget << " threads " << threads << " leaf " << i;
        ASSERT_EQ(parallel[i].centre.inliers, serial[i].centre.inliers) << "budget " << budget << " leaf " << i;
        ASSERT_EQ(parallel[i].centre.pose.x, serial[i].centre.pose.x) << "budget " << budget << " leaf " << i;
        ASSERT_EQ(parallel[i].centre.pose.theta, serial[i].centre.pose.theta) << "budget " << budget << " leaf " << i;
      }
    }
  }
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
