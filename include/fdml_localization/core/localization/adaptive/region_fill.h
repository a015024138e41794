/**
 * @file region_fill.h
 * @brief Both engines' last look at the places their seeds missed (issue 16): the leaves (the
 *        voxel engine's voxels as leaves, voxelLeaf()) reaching the best candidate's consensus
 *        that hold no candidate are searched through their sub-boxes (pruned by the box bound),
 *        the best verified pose refined; a pose explaining as many readings as the best candidate
 *        (or more) joins the candidates. Where the readings leave a continuum (few finite ranges,
 *        alike rooms), one region of leaves can hold several places and the seeds' polish reaches
 *        some and not others; this finds the rest.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Adds to @p result (ranked, de-duplicated, at most max_candidates) the places its
 *        candidates miss. Open: the @p leaves reaching the best candidate's net consensus whose
 *        box holds the pose (within the uniqueness margins) of no candidate reaching it; a leaf
 *        whose centre lies within 3 sigma of such a candidate's covariance grown by the leaf's
 *        size is on its continuum (a candidate short of the consensus accounts for no leaf).
 *        Open too: a leaf within the margins of a candidate at that consensus, short of exact (RMS
 *        1 um or more) that does not hold its pose, or on the continuum of such a candidate that
 *        accounts for it: its own place, searched first (30,000 box tests), a better place there
 *        replacing it or joining beside it.
 *        Those whose bound exceeds the consensus are screened first (screenLeaf(), three
 *        halvings, 300,000 box tests in all), those at it probed (probeLeaf(), another 100,000, or
 *        1,600,000 / k where fewer than 16 readings make box tests cheaper): a leaf with no
 *        sub-box reaching its bound has its bound lowered by one, the others are ranked by their
 *        best (probed: first) sub-box centre where better than theirs. Searched
 *        first the leaves whose bound exceeds the consensus (highest first; a place
 *        there raises it), then round robin over their connected regions (26 neighbours,
 *        @p theta_cells heading cells around the circle: every region's best leaf by its centre's
 *        agreement at the leaf's scale (closerAgreement()) then by its centre, then, tier by tier
 *        (agreeing with the consensus at the leaf's scale, missing one reading, ...), its second,
 *        ..., further leaves only while no place was found in the region, when their centre
 *        explains within two readings of the consensus or that agreement reaches it), then, while the
 *        budget lasts, the leaves left: of regions holding a place, those a place found by this
 *        fill lies in, and those on the continuum of a candidate whose RMS is within
 *        @p settings' noise_sigma and the best candidate's (or exact, where that is), or of an
 *        exact place found (a continuum missing the readings by more holds no leaf back; a place in a leaf on a
 * continuum joins only when better than its candidate or place: the first place found in a region can be a local
 * optimum of the residual). At least 64 leaves, more while their box tests stay within 100,000, and 50,000 more for
 *        leaves whose bound exceeds the best place found (the answer then provably incomplete).
 *        Each leaf is searched through its sub-boxes (searchLeafForPlace()), the best centre
 *        refined with @p settings scaled to its sub-box, and again for one reading more while its
 *        bound exceeds the place found.
 * @return the leaves searched
 */
int fillUncoveredRegions(const MapRayCaster& map, const std::vector<LeafBox>& leaves, std::int64_t theta_cells,
                         const std::vector<Reading>& readings, const LocalizerOptions& options,
                         const RefinementSettings& settings, Result& result);

}  // namespace core
}  // namespace fdml_localization
