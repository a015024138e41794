// The adaptive engine's last look at the places its seeds missed (region_fill.h).
#include "fdml_localization/core/localization/adaptive/region_fill.h"

#include "fdml_localization/core/localization/adaptive/fill_accounting.h"
#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/ranking.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Leaves at the best consensus (spread over them) checked, besides as many whose bound exceeds
/// it; those holding no candidate get their centre pose verified and are searched
/// (searchLeafForPlace(); the order is fillUncoveredRegions()'s) ...
constexpr std::size_t kFillLeaves = 20000;
/// ... at least this many of them (where as many are open) ...
constexpr int kFillTries = 64;
/// ... or, beyond those, while the leaves' box tests (searchLeafForPlace()) stay within this many,
/// or within kFillReadingTests reading tests where fewer readings make each box test cheaper ...
constexpr long kFillBoxTests = 100000;
/// ... (few readings leave thousands of leaves tied: 4 readings among a warehouse's racks, 13,065
/// in the truth's region, the truth's leaf searched after 100,000 box tests and found in 8).
constexpr long kFillReadingTests = 1600000;
/// Leaves whose bound exceeds the best place found (the answer then provably incomplete) may
/// spend this many more: many no-returns of a short range leave thousands of such leaves.
constexpr long kBeyondBoxTests = 50000;
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
/// Box tests the search of the leaves of a best candidate's own place (within its uniqueness
/// margins, not holding its pose) may spend, before the other open leaves: a better place there
/// replaces it.
constexpr long kOwnPlaceBoxTests = 30000;
/// fillPass()'s pass over those leaves.
constexpr int kOwnPlacePass = -1;
/// A place found this many leaves (in x, y and heading) from a candidate is that candidate's.
constexpr double kNearLeaves = 3.0;

/// @p box_tests box tests, or @p reading_tests reading tests where fewer readings make each cheaper: whichever is more.
long testBudget(long box_tests, long reading_tests, const std::vector<Reading>& readings)
{
  return std::max(box_tests, reading_tests / std::max<long>(1, static_cast<long>(readings.size())));
}

/// True when @p candidate accounts for the leaves its continuum reaches: RMS within @p noise [m]. Beside a larger RMS
/// an exact place can lie on the continuum (4 cones driving, a candidate of 25 mm with a standard deviation of 14.9 m
/// along a corridor reached the truth's leaf 5.1 m away, left to pass 1 and never searched: verification seed 802).
bool settled(const Candidate& candidate, double noise)
{
  return candidate.rms_residual <= noise;
}

/// A leaf no candidate accounts for, with its centre pose's net consensus and its region.
struct OpenLeaf
{
  const LeafBox* leaf;
  Candidate centre;
  int region;  ///< label of its connected region of leaves reaching the target
  int rank;    ///< 0 for its region's best centre, 1 for the next, ...
  /// Readings a pose in the leaf may explain: its count, less one where its screen left no
  /// sub-box reaching the count.
  int bound;
  /// The candidate whose continuum reaches the leaf (inliers -1: none): a place found in the
  /// leaf joins only when better than it; the leaf waits for pass 1 where the rival is settled().
  Candidate rival;
  /// Within the uniqueness margins of a candidate at the best consensus (its rival), not holding
  /// its pose: searched first (kOwnPlacePass).
  bool own;
  /// Screened (screenLeaf()): the fill searches no leaf whose bound exceeds its target unscreened.
  bool screened;
};

/// Screens @p o (screenLeaf()) unless it was screened before, its box tests counted down in @p budget: true when no
/// sub-box reaches its bound, which then drops by one. A search costs some fifty times a screen, and most leaves whose
/// bound exceeds the target hold no sub-box reaching it (11,158 of 12,222, screenOpenLeaves()). The fill screens such a
/// leaf the screens did not reach before it searches it (fillPass()).
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
  budget = testBudget(kProbeBoxTests, kProbeReadingTests, readings);
  for (auto o = open.begin(); o != open.end() && budget > 0; ++o)
  {
    const bool none =
        o->bound == target && !probeLeaf(map, o->leaf->box, readings, options, target, kScreenDepth, o->centre, budget);
    o->bound -= none ? 1 : 0;
  }
}

/// The leaves reaching @p target that hold no candidate's pose (every one whose bound exceeds the target, the highest
/// first, up to kFillLeaves; those at the target spread, leavesToSearch()), each with its centre verified, in the order
/// they are searched: round robin over their connected regions (the best leaf of every region, then the second best,
/// ...; the best centres first within a rank). The centre of a leaf left to its own place or to a settled() rival (@p
/// noise [m]) is verified when it is searched. A region's place may lie far from its leaves' centres, on a large map
/// many separate regions reach the consensus (alike rooms, alcoves), and a continuum's candidate (sd of metres along a
/// corridor) can be an approximate place while an exact one lies on it.
std::vector<OpenLeaf> openLeaves(const MapRayCaster& map, const std::vector<LeafBox>& leaves, int target,
                                 std::int64_t theta_cells, const std::vector<Reading>& readings,
                                 const std::vector<Candidate>& candidates, const LocalizerOptions& options,
                                 double noise)
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
  for (const std::size_t l : leavesToSearch(leaves, labels, target, kFillLeaves))
  {
    const LeafBox& leaf = leaves[l];
    // A leaf that may beat the candidates is open even where one's pose lies in it; so is one
    // within the margins of a best candidate short of exact that does not hold its pose (its own
    // place, where a better pose can lie in another basin: 8.7 cm from an RMS of 0.9 mm, a random
    // 70-gon).
    const Candidate* held = accounting.holder(leaf.box);
    const bool own = held != nullptr && netConsensus(*held) >= target && held->rms_residual >= kExactRms &&
                     !leaf.box.contains(held->pose, 0.0, 0.0);
    if (leaf.count <= target && held != nullptr && !own)
    {
      continue;
    }
    OpenLeaf o{ &leaf, Candidate(), labels[l], 0, leaf.count, Candidate(), own, false };
    o.rival.inliers = -1;
    const Candidate* rival = own ? held : accounting.continuumAt(leaf.box);
    o.rival = rival != nullptr ? *rival : o.rival;
    if (own || (rival != nullptr && settled(*rival, noise)))
    {
      o.centre.inliers = -1;  // verified when searched: own places first, settled continua in pass 1
    }
    else
    {
      o.centre = verifiedCandidate(map, leaf.box.centre(), readings, options.agreement_tolerance);
    }
    open.push_back(std::move(o));
  }
  screenOpenLeaves(map, readings, options, target, open);
  std::stable_sort(open.begin(), open.end(), [](const OpenLeaf& a, const OpenLeaf& b) {
    return a.centre.inliers >= 0 && (b.centre.inliers < 0 || betterCandidate(a.centre, b.centre));
  });
  std::vector<int> ranked(static_cast<std::size_t>(regions), 0);
  for (OpenLeaf& o : open)
  {
    o.rank = ranked[static_cast<std::size_t>(o.region)]++;
  }
  std::stable_sort(open.begin(), open.end(), [](const OpenLeaf& a, const OpenLeaf& b) { return a.rank < b.rank; });
  return open;
}

/// The order the open leaves are searched in: first those whose bound exceeds @p target, the
/// highest bounds first (a place there beats the best candidate and raises the target), then all
/// of them in openLeaves()' round robin.
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

/// The fill's progress over the open leaves.
struct FillState
{
  int target;                    ///< the net consensus a place must reach
  Accounting found;              ///< the places found so far
  std::vector<Candidate> known;  ///< the candidates, then the places found
  bool changed;                  ///< known changed
  std::vector<char> placed;      ///< per region: a place was found in it
  std::vector<char> searched;    ///< per open leaf
  int tried;                     ///< leaves searched
  long budget;                   ///< box tests left
};

/// Adds a @p place found in @p leaf to the known candidates, unless one lies within kNearLeaves leaves of it (at least
/// the uniqueness margins): a place no better than that one is its near-duplicate, a better one replaces it, and
/// either way a tie widens the covariance of the one kept to cover the other (absorbTiedDuplicates()). The office
/// tracking launch once published such a near-duplicate (3 to 5 cm and 6 deg off) as the pose for half a second; and
/// with 4 readings, an exact place 8.3 cm and 3.7 deg from the truth's, its RMS smaller by rounding, replaced it and
/// its covariance of 7 mm and 0.3 deg left the truth out (verification seed 704).
void admit(const LocalizerOptions& options, const RefinementSettings& settings, const PoseBox& leaf, Candidate place,
           FillState& state)
{
  place.support = 1.0;
  state.found.add(place);
  state.changed = true;
  const double near_xy = std::max(options.uniqueness_distance, kNearLeaves * (leaf.x1 - leaf.x0));
  const double near_theta = std::max(options.uniqueness_angle, kNearLeaves * (leaf.t1 - leaf.t0));
  for (Candidate& known : state.known)
  {
    const Eigen::Vector3d d = poseDifference(place.pose, known.pose);
    if (d.head<2>().norm() > near_xy || std::abs(d.z()) > near_theta)
    {
      continue;
    }
    const bool replaces = betterCandidate(place, known);
    std::vector<Candidate> kept{ replaces ? std::move(place) : known };
    absorbTiedDuplicates({ replaces ? known : place }, near_xy, near_theta, settings.noise_sigma, kept);
    known = std::move(kept.front());
    return;
  }
  state.known.push_back(std::move(place));
}

/// searchLeafForPlace() in @p o's leaf for @p goal readings, then, while the place found explains fewer than the
/// leaf's bound, again for one more: the first place reaching the goal need not be the leaf's best (in a corridor, 29
/// of 30 readings with one contradicted, 6 mm from the truth's 30 on the same continuum). The fill settles a place
/// reaching its target (settleAlongContinua()) before it meets its rival: on a corridor's continuum, a place 5 cm
/// from an exact one ties the rival's RMS of 7 mm, and unsettled it was dropped as no better.
Candidate placeInLeaf(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                      const RefinementSettings& settings, const OpenLeaf& o, int goal, long& budget)
{
  Candidate place = searchLeafForPlace(map, *o.leaf, o.centre, readings, options, settings, goal, budget);
  while (netConsensus(place) >= goal && netConsensus(place) < o.bound)
  {
    goal = netConsensus(place) + 1;
    Candidate better = searchLeafForPlace(map, *o.leaf, o.centre, readings, options, settings, goal, budget);
    if (!betterCandidate(better, place))
    {
      break;
    }
    place = std::move(better);
  }
  return place;
}

/// True when pass 0 leaves @p box to the places found so far: one lies in it, or the continuum of
/// a settled() one (@p noise [m]) reaches it. Pass 1 searches such a leaf, @p rival then the better of itself and that
/// place: the place found first in a region can be a local optimum of the residual while an exact one lies a leaf away
/// (in a corridor, 4 of 4 readings with an rms of 11 mm, 85 cm from the truth's 0; in the warehouse, a ray grazing a
/// corner, 45 um 21 cm from it).
bool leftToFound(Accounting& found, const PoseBox& box, int pass, double noise, Candidate& rival)
{
  const Candidate* holder = found.holder(box);
  const Candidate* near = holder != nullptr ? holder : found.continuumAt(box);
  if (near == nullptr || pass == 0)
  {
    return near != nullptr && (holder != nullptr || settled(*near, noise));
  }
  if (rival.inliers < 0 || betterCandidate(*near, rival))
  {
    rival = *near;
  }
  return false;
}

/// One pass over the open leaves in @p order. Pass 0 leaves for pass 1 (while the budget lasts) the leaves of
/// regions holding a place and those on a settled() candidate's continuum: mostly they hold those places again.
void fillPass(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
              const RefinementSettings& settings, std::vector<OpenLeaf>& open, const std::vector<std::size_t>& order,
              int pass, FillState& state)
{
  for (const std::size_t i : order)
  {
    OpenLeaf& o = open[i];
    // A leaf whose bound exceeds the target may hold a better place: it is searched for one.
    const bool beyond = o.bound > state.target;
    const bool promising =
        beyond || (o.centre.inliers >= 0 && netConsensus(o.centre) >= state.target - kPromisingSlack);
    const bool deferred = !beyond && ((o.rival.inliers >= 0 && settled(o.rival, settings.noise_sigma)) ||
                                      (state.placed[static_cast<std::size_t>(o.region)] && !promising));
    if (state.budget + (beyond ? kBeyondBoxTests : 0) <= 0 && (pass != 0 || state.tried >= kFillTries))
    {
      return;
    }
    Candidate rival = o.rival;
    if (state.searched[i] || o.bound < state.target || (pass == 0 && deferred) || (pass == kOwnPlacePass && !o.own) ||
        (!beyond && leftToFound(state.found, o.leaf->box, pass, settings.noise_sigma, rival)))
    {
      continue;
    }
    if (beyond && screenedOut(map, readings, options, o, state.budget))
    {
      continue;
    }
    state.searched[i] = 1;
    ++state.tried;
    if (o.centre.inliers < 0)
    {
      o.centre = verifiedCandidate(map, o.leaf->box.centre(), readings, options.agreement_tolerance);
    }
    Candidate place =
        placeInLeaf(map, readings, options, settings, o, beyond ? state.target + 1 : state.target, state.budget);
    if (netConsensus(place) >= state.target)
    {
      settleAlongContinua(map, readings, settings, place);  // before it meets its rival (placeInLeaf())
    }
    if (netConsensus(place) >= state.target && (rival.inliers < 0 || betterCandidate(place, rival)))
    {
      state.target = netConsensus(place);
      state.placed[static_cast<std::size_t>(o.region)] = 1;
      admit(options, settings, o.leaf->box, std::move(place), state);
    }
  }
}

}  // namespace

int fillUncoveredRegions(const MapRayCaster& map, const std::vector<LeafBox>& leaves, std::int64_t theta_cells,
                         const std::vector<Reading>& readings, const LocalizerOptions& options,
                         const RefinementSettings& settings, Result& result)
{
  if (result.candidates.empty())
  {
    return 0;
  }
  int target = netConsensus(result.candidates.front());
  std::vector<OpenLeaf> open =
      openLeaves(map, leaves, target, theta_cells, readings, result.candidates, options, settings.noise_sigma);
  FillState state{ target, Accounting(options), result.candidates, false, {}, std::vector<char>(open.size(), 0),
                   0,      kFillBoxTests };
  int regions = 0;
  for (const OpenLeaf& o : open)
  {
    regions = std::max(regions, o.region + 1);
  }
  state.placed.assign(static_cast<std::size_t>(regions), 0);
  const std::vector<std::size_t> order = searchOrder(open, target);
  state.budget = kOwnPlaceBoxTests;
  fillPass(map, readings, options, settings, open, order, kOwnPlacePass, state);
  state.budget = testBudget(kFillBoxTests, kFillReadingTests, readings);
  for (int pass = 0; pass < 2; ++pass)
  {
    fillPass(map, readings, options, settings, open, order, pass, state);
  }
  if (state.changed)
  {
    result.candidates = rankAndAbsorbDuplicates(state.known, options.uniqueness_distance, options.uniqueness_angle,
                                                settings.noise_sigma, options.max_candidates);
  }
  return state.tried;
}

}  // namespace core
}  // namespace fdml_localization
