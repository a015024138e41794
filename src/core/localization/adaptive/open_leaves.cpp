// The leaves the region fill searches, and their order (open_leaves.h).
#include "fdml_localization/core/localization/adaptive/open_leaves.h"

#include "fdml_localization/core/localization/adaptive/fill_accounting.h"
#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Leaves at the best consensus (spread over them) checked, besides as many whose bound exceeds
/// it; those holding no candidate get their centre pose verified.
constexpr std::size_t kFillLeaves = 20000;
/// Box tests the screens of the open leaves whose bound exceeds the best candidate (screenLeaf())
/// may spend in all, the highest bounds first (the fill screens the others before it searches
/// them, fillPass()): 2 returns and 28 no-returns of 1.1 m left 12,222 such leaves on a random
/// 70-gon, screened in 228,000 box tests (0.5 s), and the truth's leaf, among the last, then held
/// the best centre of all ...
constexpr long kScreenBoxTests = 300000;
/// ... each leaf halved this many times (a 62 cm, 5.6 deg leaf down to 7.8 cm, 0.7 deg).
constexpr int kScreenDepth = 3;
/// Box tests the probes of the open leaves at the best candidate's consensus may spend in all ...
constexpr long kProbeBoxTests = 100000;
/// ... or, where fewer readings make each box test cheaper, this many reading tests: with 4
/// readings, 10,721 leaves reach 4 on a random 70-gon and 100,000 box tests never probed the
/// truth's leaf (its centre explains 2, a sub-box's 4).
constexpr long kProbeReadingTests = 1600000;

/// A probe (probeLeaf()) made ahead of its turn, with the budget left when it was made.
struct Probe
{
  bool reaches = true;
  long used = 0;  ///< box tests
  Candidate centre;
};

/// Screens (screenLeaf()) the @p open leaves whose bound exceeds @p target (the answer then provably incomplete) while
/// kScreenBoxTests last, the highest bounds first: their bound tightened, their centre the best of their deepest
/// sub-boxes'. Box tests are cheap beside the verifications and refinements of a leaf's search, and most such leaves
/// hold no place (in a corridor with 13 short no-returns of 16 readings, 305 of 5,251 keep a sub-box 7.8 cm wide).
/// Leaves at the target are probed instead (probeLeaf(), in their spread order while kProbeBoxTests or
/// kProbeReadingTests last): a screen costs a quarter more time where readings are mostly no-returns. In a floor plan
/// of half-metre corridors, 2,392 of 3,879 leaves held no sub-box reaching the target, and the truth's leaf, its centre
/// explaining none of 6 readings, ranked 29th in its region and was never searched; probed, its centre explains 6 and
/// it ranks first.
void screenOpenLeaves(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                      int target, std::vector<OpenLeaf>& open)
{
  std::vector<std::size_t> order(open.size());
  std::iota(order.begin(), order.end(), std::size_t{ 0 });
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return open[a].bound > open[b].bound; });
  long budget = kScreenBoxTests;
  for (std::size_t j = 0; j < order.size() && budget > 0 && open[order[j]].bound > target; ++j)
  {
    screenedOut(map, readings, options, open[order[j]], budget);
  }
  probeOpenLeaves(map, readings, options, target, testBudget(kProbeBoxTests, kProbeReadingTests, readings), open);
}

/// The centres of the @p open leaves listed in @p which verified, with their agreement at the leaf's scale
/// (verifiedBox()), in parallel: each leaf's own, the same on any number of threads.
void verifyCentres(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                   const std::vector<std::size_t>& which, std::vector<OpenLeaf>& open)
{
  const long n = static_cast<long>(which.size());
#pragma omp parallel for schedule(dynamic, 64) num_threads(threadsFor(options.threads)) if (n >= 256)
  for (long j = 0; j < n; ++j)
  {
    OpenLeaf& o = open[which[static_cast<std::size_t>(j)]];
    o.centre = verifiedBox(map, o.leaf->box, readings, options.agreement_tolerance, o.agreement);
  }
}

/// The order of the leaves within a rank of openLeaves()' round robin: those whose centre is verified
/// first, the best agreeing at the leaf's own scale first (closerAgreement()), then the best
/// centre. By its centre, with 4 cones of 40 deg on a random 70-gon where 18,615 leaves reach 4,
/// the truth's leaf (its centre explaining 2 within eps) ranked 1,855th in its region and was never
/// searched; by its agreement, 48th (verification seed 810).
bool rankedBefore(const OpenLeaf& a, const OpenLeaf& b)
{
  if (a.centre.inliers < 0 || b.centre.inliers < 0)
  {
    return a.centre.inliers >= 0 && b.centre.inliers < 0;
  }
  if (closerAgreement(a.agreement, b.agreement) || closerAgreement(b.agreement, a.agreement))
  {
    return closerAgreement(a.agreement, b.agreement);
  }
  return betterCandidate(a.centre, b.centre);
}

/// The tier of @p o in the round robin (rankWithinRegions()): 0 for its region's best leaf, else the readings of
/// @p target its centre misses at the leaf's own scale (its agreement).
int roundRobinTier(const OpenLeaf& o, int target)
{
  return o.rank == 0 ? 0 : std::max(0, target - o.agreement.within);
}

/// Ranks @p open within each of its @p regions (rankedBefore()) and sorts it into the round robin: every region's best
/// leaf, then tier by tier (roundRobinTier(): the leaves agreeing with @p target at their own scale, then those missing
/// one reading, ...), by rank within a tier. With 4 cones driving in a building, 8,598 leaves in 159 regions reached 4;
/// the truth's leaf, agreeing with 3, ranked 22nd in its region, and the fill's budget ran out after 1,558 leaves
/// before that rank's round (verification seed 820); 1,045 leaves agree with 3 or more, and tiered it is reached.
void rankWithinRegions(int regions, int target, std::vector<OpenLeaf>& open)
{
  std::stable_sort(open.begin(), open.end(), rankedBefore);
  std::vector<int> ranked(static_cast<std::size_t>(regions), 0);
  for (OpenLeaf& o : open)
  {
    o.rank = ranked[static_cast<std::size_t>(o.region)]++;
  }
  std::stable_sort(open.begin(), open.end(), [target](const OpenLeaf& a, const OpenLeaf& b) {
    const int tier_a = roundRobinTier(a, target), tier_b = roundRobinTier(b, target);
    return tier_a != tier_b ? tier_a < tier_b : a.rank < b.rank;
  });
}

}  // namespace

long testBudget(long box_tests, long reading_tests, const std::vector<Reading>& readings)
{
  return std::max(box_tests, reading_tests / std::max<long>(1, static_cast<long>(readings.size())));
}

bool accountsFor(const Candidate& candidate, int target, double settled)
{
  return netConsensus(candidate) >= target && candidate.rms_residual <= settled;
}

bool screenedOut(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                 OpenLeaf& o, long& budget)
{
  if (o.screened)
  {
    return false;
  }
  o.screened = true;
  const bool out = !screenLeaf(map, o.leaf->box, readings, options, o.bound, kScreenDepth, o.centre, budget);
  o.bound -= out ? 1 : 0;
  return out;
}

// A probe is never cut short unless the budget runs out during it, so the probes are made a few per thread at a time,
// each with the budget left before them, and taken in order: one whose tests fit in what the earlier ones left is what
// the serial loop makes; the one that does not is probed again with that.
void probeOpenLeaves(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                     int target, long budget, std::vector<OpenLeaf>& open)
{
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < open.size(); ++i)
  {
    if (open[i].bound == target)
    {
      at.push_back(i);
    }
  }
  const int threads = threadsFor(options.threads);
  const std::size_t batch = 4 * static_cast<std::size_t>(threads);
  for (std::size_t first = 0; first < at.size() && budget > 0; first += batch)
  {
    const long n = static_cast<long>(std::min(batch, at.size() - first));
    std::vector<Probe> probes(static_cast<std::size_t>(n));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (n >= 2)
    for (long j = 0; j < n; ++j)
    {
      Probe& p = probes[static_cast<std::size_t>(j)];
      const OpenLeaf& o = open[at[first + static_cast<std::size_t>(j)]];
      p.centre = o.centre;
      long left = budget;
      p.reaches = probeLeaf(map, o.leaf->box, readings, options, target, kScreenDepth, p.centre, left);
      p.used = budget - left;
    }
    for (long j = 0; j < n && budget > 0; ++j)
    {
      Probe& p = probes[static_cast<std::size_t>(j)];
      OpenLeaf& o = open[at[first + static_cast<std::size_t>(j)]];
      if (p.used > budget)  // the budget runs out in this probe: made again with what is left
      {
        p.centre = o.centre;
        p.reaches = probeLeaf(map, o.leaf->box, readings, options, target, kScreenDepth, p.centre, budget);
      }
      else
      {
        budget -= p.used;
      }
      o.centre = std::move(p.centre);
      o.bound -= p.reaches ? 0 : 1;
    }
  }
}

std::vector<OpenLeaf> openLeaves(const MapRayCaster& map, const std::vector<LeafBox>& leaves, int target,
                                 std::int64_t theta_cells, const std::vector<Reading>& readings,
                                 const std::vector<Candidate>& candidates, const LocalizerOptions& options,
                                 double settled)
{
  Accounting accounting(options);
  for (const Candidate& c : candidates)
  {
    if (netConsensus(c) >= target)  // one short of the target accounts for no leaf reaching it
    {
      accounting.add(c);
    }
  }
  int regions = 0;
  const std::vector<int> labels = leafComponents(leaves, target, theta_cells, regions);
  // Spread over all alike, the voxel engine's 147,000 voxels reaching 3 of 5 readings (turning
  // in the warehouse) skipped the truth's, one of the few reaching 5.
  std::vector<OpenLeaf> open;
  std::vector<std::size_t> unverified;  // indices into open
  for (const std::size_t l : leavesToSearch(leaves, labels, target, kFillLeaves))
  {
    const LeafBox& leaf = leaves[l];
    // A leaf that may beat the candidates is open even where one's pose lies in it; so is one
    // within the margins of a best candidate short of exact that does not hold its pose (its own
    // place, where a better pose can lie in another basin: 8.7 cm from an RMS of 0.9 mm, a random
    // 70-gon).
    const Candidate* held = accounting.holder(leaf.box);
    const bool own = held != nullptr && held->rms_residual >= kExactRms && !leaf.box.contains(held->pose, 0.0, 0.0);
    if (leaf.count <= target && held != nullptr && !own)
    {
      continue;
    }
    OpenLeaf o{ &leaf, Candidate(), labels[l], 0, leaf.count, Candidate(), own, false, BoxAgreement() };
    o.rival.inliers = -1;  // none
    const Candidate* rival = own ? held : accounting.continuumAt(leaf.box);
    const bool accounted = rival != nullptr && accountsFor(*rival, target, settled);
    if (rival != nullptr)
    {
      o.rival = *rival;
    }
    // The continuum of one short of exact is its own place too: turning with 4 cones of 40 deg, the truth's leaf lay
    // 4.8 cm and 21 deg along that of the best candidate (6.5 mm), beyond its margins (verification seed 810).
    o.own = own || (accounted && rival->rms_residual >= kExactRms);
    o.centre.inliers = -1;  // unset: verified below, or when searched in pass 1 where accounted for
    if (!accounted || o.own)
    {
      unverified.push_back(open.size());
    }
    open.push_back(std::move(o));
  }
  verifyCentres(map, readings, options, unverified, open);
  screenOpenLeaves(map, readings, options, target, open);
  rankWithinRegions(regions, target, open);
  return open;
}

std::vector<std::size_t> searchOrder(const std::vector<OpenLeaf>& open, int target)
{
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < open.size(); ++i)
  {
    if (open[i].bound > target)
    {
      order.push_back(i);
    }
  }
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return open[a].bound > open[b].bound; });
  for (std::size_t i = 0; i < open.size(); ++i)
  {
    order.push_back(i);
  }
  return order;
}

}  // namespace core
}  // namespace fdml_localization
