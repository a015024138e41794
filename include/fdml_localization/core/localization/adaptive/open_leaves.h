/**
 * @file open_leaves.h
 * @brief The leaves the region fill (region_fill.h) searches: those reaching its target that no
 *        candidate accounts for, screened or probed, ranked, and the order they are searched in.
 *        Internal to the fill.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// @p box_tests box tests, or @p reading_tests reading tests where fewer readings make each cheaper: whichever is more.
long testBudget(long box_tests, long reading_tests, const std::vector<Reading>& readings);

/// True when @p candidate accounts for the leaves its continuum reaches: it reaches @p target (net consensus) and its
/// RMS is within @p settled [m] (the fill's: noise_sigma, or the best candidate's RMS where smaller). Beside a larger
/// RMS an exact place can lie on the continuum (4 cones driving, a candidate of 25 mm with a standard deviation of
/// 14.9 m along a corridor reached the truth's leaf 5.1 m away, left to pass 1 and never searched: verification seed
/// 802); one short of the target, a place there beats it (seed 805).
bool accountsFor(const Candidate& candidate, int target, double settled);

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
  /// leaf joins only when better than it; the leaf waits for pass 1 where the rival accountsFor() it.
  Candidate rival;
  /// Its rival's own place, searched first (kOwnPlacePass): within the uniqueness margins of a
  /// candidate at the best consensus, not holding its pose, or on the continuum of one short of
  /// exact (RMS kExactRms or more) that accountsFor() it.
  bool own;
  /// Screened (screenLeaf()): the fill searches no leaf whose bound exceeds its target unscreened.
  bool screened;
  /// Its centre's agreement at the leaf's scale (verifiedBox()), its rank's first key.
  BoxAgreement agreement;
};

/// Screens @p o (screenLeaf()) unless it was screened before, its box tests counted down in @p budget: true when no
/// sub-box reaches its bound, which then drops by one. A search costs some fifty times a screen, and most leaves whose
/// bound exceeds the target hold no sub-box reaching it (11,158 of 12,222, screenOpenLeaves()). The fill screens such a
/// leaf the screens did not reach before it searches it (fillPass()).
bool screenedOut(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                 OpenLeaf& o, long& budget);

/// The leaves reaching @p target that hold no candidate's pose (every one whose bound exceeds the target, the highest
/// first, up to kFillLeaves; those at the target spread, leavesToSearch()), each with its centre verified, in the order
/// they are searched: round robin over their connected regions (the best leaf of every region, then, tier by tier, the
/// leaves whose centre agrees with @p target at the leaf's scale, then those missing one reading, ..., within a tier
/// the second best of every region, then the third, ...; the best first within a rank), the best agreeing best at the
/// leaf's own scale (closerAgreement()), then the best centre. The centre of a leaf left to an exact rival that
/// accountsFor() it (@p settled [m]) is verified when it is searched. A region's place may lie far from its leaves'
/// centres, on a large map many separate regions reach the consensus (alike rooms, alcoves), and a continuum's
/// candidate (sd of metres along a corridor) can be an approximate place while an exact one lies on it.
std::vector<OpenLeaf> openLeaves(const MapRayCaster& map, const std::vector<LeafBox>& leaves, int target,
                                 std::int64_t theta_cells, const std::vector<Reading>& readings,
                                 const std::vector<Candidate>& candidates, const LocalizerOptions& options,
                                 double settled);

/// Probes (probeLeaf()) the @p open leaves whose bound is @p target, in their order, while @p budget box tests last: a
/// leaf holding no sub-box reaching the target loses a point of its bound, and the centre of one that does becomes that
/// sub-box's where better. The probes run in parallel (LocalizerOptions::threads), with the same answer as one after
/// the other on any number of threads.
void probeOpenLeaves(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                     int target, long budget, std::vector<OpenLeaf>& open);

/// The order the open leaves are searched in: first those whose bound exceeds @p target, the
/// highest bounds first (a place there beats the best candidate and raises the target), then all
/// of them in openLeaves()' round robin.
std::vector<std::size_t> searchOrder(const std::vector<OpenLeaf>& open, int target);

}  // namespace core
}  // namespace fdml_localization
