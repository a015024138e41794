/**
 * @file leaf_search.h
 * @brief The search of one box of poses (an adaptive leaf) for a place explaining a given number
 *        of readings (issue 16): the region fill's tool (region_fill.h).
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/// Lattice points per axis inside each leaf leafLatticeBests() verifies.
constexpr int kLeafLattice = 3;

/**
 * @brief The best exactly verified pose (agreement band @p eps [m]) of a kLeafLattice^3 lattice
 *        in each of @p leaves, at most @p max_leaves of them spread evenly over the list.
 */
std::vector<Candidate> leafLatticeBests(const MapRayCaster& map, const std::vector<const LeafBox*>& leaves,
                                        std::size_t max_leaves, const std::vector<Reading>& readings, double eps);

/**
 * @brief The refinement of a lattice pose in a leaf (or voxel) of @p cell_xy [m] by
 *        @p cell_theta [rad]: seeded one leaf from the optimum, at least eps wide.
 */
RefinementSettings latticeRefinement(const LocalizerOptions& options, double cell_xy, double cell_theta);

/// How well a box's centre agrees with the readings at the box's own scale.
struct BoxAgreement
{
  int within = -1;    ///< readings explained within the band a pose of the box allows (-1: not verified)
  double cost = 0.0;  ///< their sum of squared residuals, each relative to its band
};

/// More readings within their bands, then the smaller relative cost.
bool closerAgreement(const BoxAgreement& a, const BoxAgreement& b);

/**
 * @brief The centre of @p box verified (agreement band @p eps [m]), and in @p agreement its
 *        agreement at the box's scale: the band within which the centre may miss a reading while
 *        a pose of the box explains it is eps plus half the box's diagonal in x, y plus half its
 *        heading span times the reading's reach (mounting offset plus range).
 */
Candidate verifiedBox(const MapRayCaster& map, const PoseBox& box, const std::vector<Reading>& readings, double eps,
                      BoxAgreement& agreement);

/// A pose explaining at least the target less this many readings is promising: refined, and its
/// leaf searched even where its region already holds a place (region_fill.h).
constexpr int kPromisingSlack = 2;

/**
 * @brief The best pose found in @p leaf for @p target readings: its sub-boxes level by level
 *        (every axis halved, four times: a 75 cm, 5.6 deg leaf down to 4.7 cm and 0.35 deg; six
 *        times, down to 1.2 cm and 0.09 deg, while the best centre explains within two readings
 *        of the target), only those that may still explain @p target readings
 *        (boxConsensusBound(), range_tolerance), at most 16 per level: those whose centres
 *        explain the most readings within the band a pose of the box allows (eps, half the box's
 *        diagonal and half its heading span times the reading's reach), then with the least
 *        residuals relative to it. The best verified centre so far is refined (refineSeed() with
 *        @p settings, its scales set to the centre's sub-box, on the centre's inliers and every
 *        reading the sub-box's box test keeps) once it explains within two readings of the
 *        target, or from the fourth level on; where none is that close, at the fourth level the
 *        first sub-box of the beam is refined too when its centre explains within two readings
 *        of the target within the bands (with readings of 11 m, the centre of the truth's 4.7 cm,
 *        0.35 deg sub-box explains 2 of 5 within eps and 3 within the bands). A refinement is kept when
 *        it stays within two leaves of its start; the search stops at a pose in the leaf (or within half its size)
 * reaching the target, exact or with an RMS of a tenth of noise_sigma or more (near noise-free readings, an exact place
 * can lie a few millimetres from a place short of it; a refinement that goes further found another leaf's place).
 * Where it stops at a place short of exact, the next three sub-boxes of that level are refined too and the best place
 * near the leaf kept (a local optimum of 7.3 mm can lie 1.8 cm from an exact place in the same leaf).
 * Where rays graze corners or short no-return ranges shape it, a place can be a few centimetres or millimetres wide: a
 * lattice of the whole leaf misses it.
 * @param centre the leaf's centre, verified (the answer when nothing better is found)
 * @param box_tests counted down by the box tests made (the search of a leaf is never cut)
 */
Candidate searchLeafForPlace(const MapRayCaster& map, const LeafBox& leaf, const Candidate& centre,
                             const std::vector<Reading>& readings, const LocalizerOptions& options,
                             const RefinementSettings& settings, int target, long& box_tests);

/**
 * @brief The first sub-box of @p box, @p depth halvings of every axis down, that may explain
 *        @p needed readings (boxConsensusBound(), band @p tolerance [m]), searched depth first:
 *        none, and no pose in @p box explains that many. The certificate's exclusion of a region
 *        and the region fill's probe of a leaf (probeLeaf()).
 * @param budget counted down by the box tests made; once spent, the box at hand counts as
 *        reaching (the answer stays conservative)
 * @param found set to that sub-box when the answer is true
 */
bool firstSubBoxReaching(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance,
                         const PoseBox& box, int needed, int depth, long& budget, PoseBox& found);

/**
 * @brief The probe of a leaf at the region fill's target: firstSubBoxReaching() @p needed
 *        readings (range_tolerance) @p depth halvings down. None: false. Else @p centre (when
 *        verified, inliers >= 0) becomes that sub-box's verified centre where better. Cheaper than
 *        screenLeaf() (one sub-box, not all): where ranges are short beside a leaf (corridors
 *        half a metre wide, 14 cm leaves), a leaf's own centre explains none of the readings its
 *        place explains, and most leaves reaching the target hold no sub-box that does.
 * @param box_tests counted down by the box tests made
 */
bool probeLeaf(const MapRayCaster& map, const PoseBox& leaf, const std::vector<Reading>& readings,
               const LocalizerOptions& options, int needed, int depth, Candidate& centre, long& box_tests);

/**
 * @brief The screen of a leaf before its search: its sub-boxes @p depth halvings of every axis
 *        down that may explain @p needed readings, by box tests alone (boxConsensusBound(),
 *        range_tolerance). None left: no pose in @p leaf explains that many. Else @p centre
 *        becomes the best verified centre of the deepest ones (at most 8 of them, spread) where
 *        better than it (or unset, inliers < 0): where most readings are short no-returns, the
 *        leaf's own centre, 40 cm from a place in its corner, explains 4 of 16 readings while a
 *        sub-box's explains 15.
 * @param box_tests counted down by the box tests made (at most 8 + 64 + ... per leaf)
 * @return whether some sub-box may explain @p needed readings
 */
bool screenLeaf(const MapRayCaster& map, const PoseBox& leaf, const std::vector<Reading>& readings,
                const LocalizerOptions& options, int needed, int depth, Candidate& centre, long& box_tests);

}  // namespace core
}  // namespace fdml_localization
