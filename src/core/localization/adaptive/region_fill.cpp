// The adaptive engine's last look at the places its seeds missed (region_fill.h).
#include "fdml_localization/core/localization/adaptive/region_fill.h"

#include "fdml_localization/core/localization/adaptive/fill_accounting.h"
#include "fdml_localization/core/localization/adaptive/open_leaves.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Open leaves (openLeaves()) searched (searchLeafForPlace(), in searchOrder()): at least this many (where as many
/// are open) ...
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
/// Box tests the search of the leaves of a best candidate's own place (within its uniqueness
/// margins, not holding its pose) may spend, before the other open leaves: a better place there
/// replaces it.
constexpr long kOwnPlaceBoxTests = 30000;
/// fillPass()'s pass over those leaves.
constexpr int kOwnPlacePass = -1;
/// A place found this many leaves (in x, y and heading) from a candidate is that candidate's.
constexpr double kNearLeaves = 3.0;

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
  double settled;                ///< the RMS [m] within which a candidate accountsFor() its continuum
};

/// Adds a @p place found in @p leaf to the known candidates, unless one lies within kNearLeaves leaves of it (at least
/// the uniqueness margins): a place no better than that one is its near-duplicate, a better one replaces it, and
/// either way a tie widens the covariance of the one kept to cover the other (absorbTiedDuplicates()). The office
/// tracking launch once published such a near-duplicate (3 to 5 cm and 6 deg off) as the pose for half a second; and
/// with 4 readings, an exact place 8.3 cm and 3.7 deg from the truth's, its RMS smaller by rounding, replaced it and
/// its covariance of 7 mm and 0.3 deg left the truth out (verification seed 704). An exact tie (exactTie()) never
/// replaces: what the one known absorbed would be lost (seed 806: the truth's place, having absorbed a place 3.4 cm and
/// 5 deg from it, was replaced by it, and a second such replacement left the truth uncovered).
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
    const bool replaces = !exactTie(place, known) && betterCandidate(place, known);
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

/// True when pass 0 leaves @p box to the places found so far: one lies in it, or the continuum of an exact one that
/// accountsFor() it (@p target, @p settled [m]) reaches it. Short of exact, a place found can be a local optimum beside
/// the exact one (verification seed 814, 4 cones: a place of 6.8 mm 10 deg from the exact truth, its heading's sd of
/// 5.3 deg reaching the truth's leaf, which waited for pass 1 and was never searched). Pass 1 searches such a leaf,
/// @p rival then the better of itself and that place: the place found first in a region can be a local optimum of the
/// residual while an exact one lies a leaf away (in a corridor, 4 of 4 readings with an rms of 11 mm, 85 cm from the
/// truth's 0; in the warehouse, a ray grazing a corner, 45 um 21 cm from it).
bool leftToFound(Accounting& found, const PoseBox& box, int pass, int target, double settled, Candidate& rival)
{
  const Candidate* holder = found.holder(box);
  const Candidate* near = holder != nullptr ? holder : found.continuumAt(box);
  if (near == nullptr || pass == 0)
  {
    return near != nullptr &&
           (holder != nullptr || (accountsFor(*near, target, settled) && near->rms_residual < kExactRms));
  }
  if (rival.inliers < 0 || betterCandidate(*near, rival))
  {
    rival = *near;
  }
  return false;
}

/// What fillPass() does at a leaf.
enum class Turn
{
  kStop,    ///< the pass ends (its budget spent)
  kSkip,    ///< the leaf is passed over
  kSearch,  ///< the leaf is screened where its bound exceeds the target (beyond), then searched
};

/// The turn of leaf @p i (@p o) in @p pass as @p state stands. Pass 0 leaves for pass 1 (while the budget lasts) the
/// leaves of regions holding a place that are not promising and those on the continuum of a candidate that
/// accountsFor() them: mostly they hold those places again. A leaf is promising when its centre explains within
/// kPromisingSlack readings of the target, or the target within the bands of the leaf's own scale (its agreement:
/// verification seed 811, the truth's leaf explained 1 of 6 readings at its centre and all 6 in their bands). A leaf
/// whose bound exceeds the target (@p beyond) may hold a better place: it is searched for one (@p goal: one reading
/// more than the target; else the target). @p rival is set to the candidate a place found must beat (inliers -1: none).
Turn turnOf(const OpenLeaf& o, std::size_t i, int pass, FillState& state, bool& beyond, int& goal, Candidate& rival)
{
  beyond = o.bound > state.target;
  goal = beyond ? state.target + 1 : state.target;
  const bool promising = beyond || o.agreement.within >= state.target ||
                         (o.centre.inliers >= 0 && netConsensus(o.centre) >= state.target - kPromisingSlack);
  const bool deferred = !beyond && (accountsFor(o.rival, state.target, state.settled) ||
                                    (state.placed[static_cast<std::size_t>(o.region)] && !promising));
  if (state.budget + (beyond ? kBeyondBoxTests : 0) <= 0 && (pass != 0 || state.tried >= kFillTries))
  {
    return Turn::kStop;
  }
  rival = o.rival;
  const bool skip = state.searched[i] || o.bound < state.target || (pass == 0 && deferred) ||
                    (pass == kOwnPlacePass && !o.own) ||
                    (!beyond && leftToFound(state.found, o.leaf->box, pass, state.target, state.settled, rival));
  return skip ? Turn::kSkip : Turn::kSearch;
}

/// A leaf's screen and search for @p goal readings, made on a copy of it: neither depends on the budget (they are never
/// cut short), so a search made ahead of its turn is the one its turn makes for the same goal.
struct LeafTurn
{
  int goal = -1;
  bool beyond = false;
  OpenLeaf leaf;     ///< the leaf after its screen and its centre's verification
  bool out = false;  ///< screened out: not searched
  Candidate place;
  long used = 0;  ///< box tests
};

LeafTurn takeTurn(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                  const RefinementSettings& settings, const OpenLeaf& o, bool beyond, int goal)
{
  LeafTurn t{ goal, beyond, o, false, Candidate(), 0 };
  long budget = 0;
  t.out = beyond && screenedOut(map, readings, options, t.leaf, budget);
  if (!t.out)
  {
    if (t.leaf.centre.inliers < 0)
    {
      t.leaf.centre = verifiedCandidate(map, t.leaf.leaf->box.centre(), readings, options.agreement_tolerance);
    }
    t.place = placeInLeaf(map, readings, options, settings, t.leaf, goal, budget);
  }
  t.used = -budget;
  return t;
}

/// Leaf @p i's turn @p t taken: its screen and search counted, and the place found admitted where it reaches the
/// target and beats @p rival.
void commitTurn(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                const RefinementSettings& settings, OpenLeaf& o, std::size_t i, LeafTurn t, const Candidate& rival,
                FillState& state)
{
  o = std::move(t.leaf);
  state.budget -= t.used;
  if (t.out)
  {
    return;
  }
  state.searched[i] = 1;
  ++state.tried;
  Candidate& place = t.place;
  if (netConsensus(place) >= state.target)
  {
    settleAlongContinua(map, readings, settings, place);  // before it meets its rival (placeInLeaf())
  }
  if (netConsensus(place) >= state.target && (rival.inliers < 0 || betterCandidate(place, rival)))
  {
    if (netConsensus(place) > state.target)
    {
      state.found.clear();  // the places found so far fall short of it
    }
    state.target = netConsensus(place);
    state.placed[static_cast<std::size_t>(o.region)] = 1;
    admit(options, settings, o.leaf->box, std::move(place), state);
  }
}

/// The positions in @p order from @p from on of the next @p batch leaves the pass searches as @p state stands, and
/// their turns taken ahead, in parallel.
std::vector<std::pair<std::size_t, LeafTurn>> turnsAhead(const MapRayCaster& map, const std::vector<Reading>& readings,
                                                         const LocalizerOptions& options,
                                                         const RefinementSettings& settings,
                                                         const std::vector<OpenLeaf>& open,
                                                         const std::vector<std::size_t>& order, std::size_t from,
                                                         std::size_t batch, int pass, FillState& state)
{
  std::vector<std::pair<std::size_t, LeafTurn>> ahead;
  bool beyond = false;
  int goal = 0;
  Candidate rival;
  for (std::size_t at = from; at < order.size() && ahead.size() < batch; ++at)
  {
    const Turn turn = turnOf(open[order[at]], order[at], pass, state, beyond, goal, rival);
    if (turn == Turn::kStop)
    {
      break;
    }
    if (turn == Turn::kSearch)
    {
      ahead.emplace_back(at, LeafTurn{ goal, beyond, OpenLeaf(), false, {}, 0 });
    }
  }
  const long n = static_cast<long>(ahead.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threadsFor(options.threads)) if (n >= 2)
  for (long j = 0; j < n; ++j)
  {
    auto& [at, t] = ahead[static_cast<std::size_t>(j)];
    t = takeTurn(map, readings, options, settings, open[order[at]], t.beyond, t.goal);
  }
  return ahead;
}

/// One pass over the open leaves in @p order (turnOf()). The turns are taken a few per thread ahead (turnsAhead()),
/// then in order as the state then stands: a turn taken ahead for the goal its turn has is that turn, and one whose
/// goal changed (a place found raised the target) is taken again; the same answer as one leaf after the other.
void fillPass(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
              const RefinementSettings& settings, std::vector<OpenLeaf>& open, const std::vector<std::size_t>& order,
              int pass, FillState& state)
{
  const int threads = threadsFor(options.threads);
  const std::size_t batch = threads > 1 ? 2 * static_cast<std::size_t>(threads) : 1;
  for (std::size_t at = 0; at < order.size();)
  {
    std::vector<std::pair<std::size_t, LeafTurn>> ahead =
        turnsAhead(map, readings, options, settings, open, order, at, batch, pass, state);
    const std::size_t end = ahead.empty() ? order.size() : ahead.back().first + 1;
    std::vector<std::size_t> taken;  // leaves whose turn this batch took: a leaf stands twice in order
    for (auto next = ahead.begin(); at < end; ++at)
    {
      const std::size_t i = order[at];
      bool beyond = false;
      int goal = 0;
      Candidate rival;
      const Turn turn = turnOf(open[i], i, pass, state, beyond, goal, rival);
      if (turn == Turn::kStop)
      {
        return;
      }
      while (next != ahead.end() && next->first < at)
      {
        ++next;
      }
      if (turn == Turn::kSkip)
      {
        continue;
      }
      const bool made = next != ahead.end() && next->first == at && next->second.goal == goal &&
                        next->second.beyond == beyond && std::find(taken.begin(), taken.end(), i) == taken.end();
      taken.push_back(i);
      commitTurn(map, readings, options, settings, open[i], i,
                 made ? std::move(next->second) : takeTurn(map, readings, options, settings, open[i], beyond, goal),
                 rival, state);
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
  // A candidate accounts for its continuum when its RMS is within the noise and the best candidate's: beside an exact
  // one, one of 1.8 mm held the truth's leaf back 4 m along a corridor (verification seed 807); beside a best of
  // 2.7 mm, one of 5.7 mm held it back 1.3 m away (seed 808).
  const double settled = std::min(settings.noise_sigma, std::max(kExactRms, result.candidates.front().rms_residual));
  std::vector<OpenLeaf> open =
      openLeaves(map, leaves, target, theta_cells, readings, result.candidates, options, settled);
  FillState state{
    target, Accounting(options), result.candidates, false, {}, std::vector<char>(open.size(), 0), 0, kFillBoxTests,
    settled
  };
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
