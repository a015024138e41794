// The region fill's screen and probe of a leaf (leaf_search.h): a screen that leaves no sub-box
// proves that no pose of the leaf reaches the count, it proves so more often than the leaf's own
// box bound, its ranking centre is a verified pose of the leaf, and its box tests are counted; the
// probe answers as the screen does.
#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/certificate.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <iterator>

namespace fdml_localization
{
namespace core
{
namespace
{
/// A free pose, readings in 6 random directions from a pose up to 15 cm and 4 deg from it, and a
/// box of 0.5 to 40 cm and 0.3 to 11 deg holding the free pose (not, in general, the readings').
struct ScreenCase
{
  Pose2 q;
  std::vector<Reading> readings;
  PoseBox box;
};

ScreenCase randomCase(const MapRayCaster& map, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> size(0.005, 0.4), jitter(-0.15, 0.15), heading(-kPi, kPi), frac(0.0, 1.0);
  ScreenCase c;
  c.q = test::randomFreePose(map, rng, 0.05);
  std::vector<Pose2> offsets;
  for (int i = 0; i < 6; ++i)
  {
    offsets.emplace_back(0.0, 0.0, heading(rng));
  }
  Pose2 source;
  do
  {
    source = Pose2(c.q.x + jitter(rng), c.q.y + jitter(rng), c.q.theta + 0.5 * jitter(rng));
  } while (!map.isFree(source.position()));
  c.readings = test::exactReadings(map, source, offsets);
  const double sx = size(rng), sy = size(rng), st = 0.5 * size(rng);
  c.box.x0 = c.q.x - sx * frac(rng);
  c.box.x1 = c.box.x0 + sx;
  c.box.y0 = c.q.y - sy * frac(rng);
  c.box.y1 = c.box.y0 + sy;
  c.box.t0 = c.q.theta - st * frac(rng);
  c.box.t1 = c.box.t0 + st;
  return c;
}

TEST(ScreenLeaf, AnEmptyScreenProvesNoPoseOfTheLeafReachesTheCount)
{
  const auto map = test::loadMap("maps/apartment.poly");
  LocalizerOptions options;
  options.range_tolerance = 0.03;
  std::mt19937_64 rng(77);
  int screened_out = 0, box_out = 0;
  for (int trial = 0; trial < 600; ++trial)
  {
    const ScreenCase c = randomCase(*map, rng);
    const int at_q = consensusWithin(*map, c.q, c.readings, options.range_tolerance);
    for (int needed = 4; needed <= 6; ++needed)
    {
      Candidate centre;
      centre.inliers = -1;
      long box_tests = 0;
      if (!screenLeaf(*map, c.box, c.readings, options, needed, 3, centre, box_tests))
      {
        // q lies in the box: it must explain fewer.
        ASSERT_LT(at_q, needed) << "trial " << trial << " needed " << needed;
        ++screened_out;
      }
      box_out += boxConsensusBound(*map, c.readings, options.range_tolerance, c.box, needed) < needed;
      EXPECT_LE(-box_tests, 8 + 64 + 512);
      EXPECT_GE(-box_tests, 8);
    }
  }
  // The screen proves at least what the leaf's bound proves, and more.
  EXPECT_GT(screened_out, box_out + 50) << screened_out << " against " << box_out;
}

TEST(BoxConsensusTest, AnswersAsTheBoxBoundDoesWhileItReordersTheReadings)
{
  // One test over a leaf's sub-boxes (its reading order carried from box to box, and its arcs
  // while the heading half stays the same), against boxConsensusBound() on each: the same answer
  // for every box and count, and some boxes pass and some fail.
  const auto map = test::loadMap("maps/apartment.poly");
  const double tau = 0.03;
  std::mt19937_64 rng(79);
  int passed = 0, failed = 0;
  for (int trial = 0; trial < 200; ++trial)
  {
    const ScreenCase c = randomCase(*map, rng);
    BoxConsensusTest test(*map, c.readings, tau);
    for (int sub = 0; sub < 64; ++sub)
    {
      const PoseBox box = c.box.half(sub % 8).half(sub / 8);
      for (int needed = 0; needed <= 7; ++needed)
      {
        const bool reaches = boxConsensusBound(*map, c.readings, tau, box, needed) >= needed;
        ASSERT_EQ(test.reaches(box, needed), reaches)
            << "trial " << trial << " sub-box " << sub << " needed " << needed;
        (reaches ? passed : failed) += 1;
      }
    }
  }
  EXPECT_GT(passed, 10000);
  EXPECT_GT(failed, 10000);
}

TEST(ScreenLeaf, ItsCentreIsAVerifiedPoseOfTheLeafNoWorseThanTheOneGiven)
{
  const auto map = test::loadMap("maps/apartment.poly");
  LocalizerOptions options;
  std::mt19937_64 rng(78);
  int improved = 0;
  for (int trial = 0; trial < 200; ++trial)
  {
    const ScreenCase c = randomCase(*map, rng);
    const Candidate given = verifiedCandidate(*map, c.box.centre(), c.readings, options.agreement_tolerance);
    Candidate centre = given;
    long box_tests = 0;
    if (!screenLeaf(*map, c.box, c.readings, options, 3, 3, centre, box_tests))
    {
      continue;
    }
    ASSERT_TRUE(c.box.contains(centre.pose, 1e-9, 1e-9)) << "trial " << trial;
    const Candidate again = verifiedCandidate(*map, centre.pose, c.readings, options.agreement_tolerance);
    EXPECT_EQ(again.inliers, centre.inliers);
    EXPECT_EQ(again.contradicted, centre.contradicted);
    EXPECT_FALSE(betterCandidate(given, centre)) << "trial " << trial;
    improved += betterCandidate(centre, given);
  }
  EXPECT_GT(improved, 20);
}

// The probe of a leaf at the fill's target (probeLeaf(), firstSubBoxReaching()): it answers as the
// screen does (both test the same sub-boxes, the probe depth first up to the first that reaches),
// for no more box tests; a "no" holds for a lattice of the leaf's poses; a "yes" names a sub-box of
// the leaf, three halvings down, whose bound reaches the count, and its centre is a verified pose
// of the leaf no worse than the one given.
TEST(ProbeLeaf, AnswersAsTheScreenForFewerBoxTestsAndNamesASubBoxReachingTheCount)
{
  const auto map = test::loadMap("maps/apartment.poly");
  LocalizerOptions options;
  options.range_tolerance = 0.03;
  std::mt19937_64 rng(79);
  int no = 0, yes = 0, improved = 0;
  for (int trial = 0; trial < 300; ++trial)
  {
    const ScreenCase c = randomCase(*map, rng);
    const Candidate given = verifiedCandidate(*map, c.box.centre(), c.readings, options.agreement_tolerance);
    for (int needed = 4; needed <= 6; ++needed)
    {
      Candidate screened = given, probed = given;
      long screen_tests = 0, probe_tests = 100000;  // the probe's budget is ample
      const bool screen = screenLeaf(*map, c.box, c.readings, options, needed, 3, screened, screen_tests);
      const bool probe = probeLeaf(*map, c.box, c.readings, options, needed, 3, probed, probe_tests);
      ASSERT_EQ(probe, screen) << "trial " << trial << " needed " << needed;
      EXPECT_LE(100000 - probe_tests, 1 - screen_tests);  // the screen does not count the leaf's own test
      ASSERT_TRUE(c.box.contains(probed.pose, 1e-9, 1e-9)) << "trial " << trial;
      EXPECT_FALSE(betterCandidate(given, probed));
      improved += betterCandidate(probed, given);
      long budget = 1000;
      PoseBox found;
      ASSERT_EQ(firstSubBoxReaching(*map, c.readings, options.range_tolerance, c.box, needed, 3, budget, found), probe);
      if (!probe)
      {
        ++no;
        for (int i = 0; i < 7 * 7 * 7; ++i)
        {
          const Pose2 pose(c.box.x0 + (c.box.x1 - c.box.x0) * (i % 7) / 6.0,
                           c.box.y0 + (c.box.y1 - c.box.y0) * (i / 7 % 7) / 6.0,
                           c.box.t0 + (c.box.t1 - c.box.t0) * (i / 49) / 6.0);
          ASSERT_LT(consensusWithin(*map, pose, c.readings, options.range_tolerance), needed) << "trial " << trial;
        }
        continue;
      }
      ++yes;
      EXPECT_NEAR(found.x1 - found.x0, (c.box.x1 - c.box.x0) / 8.0, 1e-12);
      EXPECT_NEAR(found.t1 - found.t0, (c.box.t1 - c.box.t0) / 8.0, 1e-12);
      EXPECT_TRUE(c.box.contains(found.centre(), 1e-9, 1e-9));
      EXPECT_GE(boxConsensusBound(*map, c.readings, options.range_tolerance, found, needed), needed);
    }
  }
  EXPECT_GT(no, 100);
  EXPECT_GT(yes, 100);
  EXPECT_GT(improved, 20);
}

// The fill's choice of leaves (leavesToSearch()): every leaf that may beat the best place is kept,
// the highest counts first, however many reach the best place's count; the rest are spread.
// A box's agreement at its own scale (verifiedBox(), the open leaves' rank, open_leaves.h): its
// candidate is the verified centre, every reading the centre explains within eps is within its
// band, and it tells the box holding the readings' pose from another box of the same size more
// often than the centre's consensus does (verification seed 810: 4 cones, the truth's leaf
// 1,855th by its centre, 48th by its agreement).
TEST(VerifiedBox, ItsAgreementFindsTheBoxHoldingThePoseMoreOftenThanItsCentre)
{
  const auto map = test::loadMap("maps/apartment.poly");
  const double eps = LocalizerOptions().agreement_tolerance;
  std::mt19937_64 rng(810);
  std::uniform_real_distribution<double> size(0.05, 0.4), heading(-kPi, kPi), frac(0.0, 1.0);
  int by_agreement = 0, by_centre = 0;
  for (int trial = 0; trial < 300; ++trial)
  {
    const Pose2 source = test::randomFreePose(*map, rng, 0.05), elsewhere = test::randomFreePose(*map, rng, 0.05);
    std::vector<Pose2> offsets;
    for (int i = 0; i < 5; ++i)
    {
      offsets.emplace_back(0.0, 0.0, heading(rng));
    }
    const std::vector<Reading> readings = test::exactReadings(*map, source, offsets);
    const double sx = size(rng), st = 0.5 * size(rng);
    const auto boxAt = [&](const Pose2& p, double fx, double fy, double ft) {
      return PoseBox{ p.x - sx * fx,         p.x + sx * (1.0 - fx), p.y - sx * fy,
                      p.y + sx * (1.0 - fy), p.theta - st * ft,     p.theta + st * (1.0 - ft) };
    };
    const double fx = frac(rng), fy = frac(rng), ft = frac(rng);
    const PoseBox holding = boxAt(source, fx, fy, ft), other = boxAt(elsewhere, fx, fy, ft);
    BoxAgreement a, b;
    const Candidate ca = verifiedBox(*map, holding, readings, eps, a);
    const Candidate cb = verifiedBox(*map, other, readings, eps, b);
    const Candidate centre = verifiedCandidate(*map, holding.centre(), readings, eps);
    EXPECT_EQ(ca.inliers, centre.inliers) << "trial " << trial;
    EXPECT_EQ(ca.contradicted, centre.contradicted) << "trial " << trial;
    EXPECT_GE(a.within, ca.inliers) << "trial " << trial;
    by_agreement += closerAgreement(a, b);
    by_centre += betterCandidate(ca, cb);
  }
  RecordProperty("by_agreement", by_agreement);
  RecordProperty("by_centre", by_centre);
  EXPECT_GT(by_agreement, by_centre + 10);
}

TEST(LeavesToSearch, KeepsEveryLeafBeyondTheTargetAndSpreadsTheRest)
{
  std::mt19937_64 rng(7);
  std::vector<LeafBox> leaves(150000);
  std::vector<int> labels(leaves.size(), 0);
  for (LeafBox& l : leaves)
  {
    l.count = 3;
  }
  std::uniform_int_distribution<std::size_t> pick(0, leaves.size() - 1);
  std::vector<std::size_t> beyond;
  for (int j = 0; j < 12; ++j)
  {
    const std::size_t l = pick(rng);
    leaves[l].count = 4 + j % 2;
    beyond.push_back(l);
  }
  labels[beyond.back()] = -1;  // in no component at the target: never searched
  std::sort(beyond.begin(), beyond.end());
  beyond.erase(std::unique(beyond.begin(), beyond.end()), beyond.end());
  const std::vector<std::size_t> chosen = leavesToSearch(leaves, labels, 3, 1000);
  std::size_t first_at_target = 0;
  while (first_at_target < chosen.size() && leaves[chosen[first_at_target]].count > 3)
  {
    ++first_at_target;
  }
  for (std::size_t l : beyond)
  {
    const bool kept = std::find(chosen.begin(), chosen.end(), l) != chosen.end();
    EXPECT_EQ(kept, labels[l] >= 0) << "leaf " << l;
  }
  EXPECT_EQ(first_at_target, static_cast<std::size_t>(std::count_if(beyond.begin(), beyond.end(),
                                                                    [&](std::size_t l) { return labels[l] >= 0; })));
  for (std::size_t j = 1; j < first_at_target; ++j)
  {
    EXPECT_GE(leaves[chosen[j - 1]].count, leaves[chosen[j]].count);
  }
  const std::size_t spread = chosen.size() - first_at_target;
  EXPECT_GE(spread, 1000u);
  EXPECT_LT(spread, 2000u);
  // The leaves beyond the target are capped at the limit too, the highest kept.
  const std::vector<std::size_t> capped = leavesToSearch(leaves, labels, 3, 2);
  ASSERT_GE(capped.size(), 2u);
  EXPECT_EQ(leaves[capped[0]].count, 5);
  EXPECT_EQ(leaves[capped[1]].count, 5);
  // A bound whose leaves overflow the limit is spread over them, not taken from one end.
  for (std::size_t l = 0; l < leaves.size(); ++l)
  {
    leaves[l].count = l % 4 == 0 ? 4 : 3;
  }
  const std::vector<std::size_t> overflow = leavesToSearch(leaves, labels, 3, 1000);
  std::vector<std::size_t> kept_beyond;
  std::copy_if(overflow.begin(), overflow.end(), std::back_inserter(kept_beyond),
               [&](std::size_t l) { return leaves[l].count == 4; });
  EXPECT_LE(kept_beyond.size(), 1000u);
  EXPECT_GE(kept_beyond.size(), 900u);
  EXPECT_GT(*std::max_element(kept_beyond.begin(), kept_beyond.end()), leaves.size() * 9 / 10);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
