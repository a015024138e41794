/**
 * @file certificate.h
 * @brief The certificate of an answer (issue 16): the largest consensus the search proved and
 *        whether every pose that may reach it lies in the returned candidates' regions.
 *
 * Both engines prune with tests that are conservative at the range tolerance tau: a box of poses
 * (adaptive) or a voxel keeps a reading whenever some pose inside it may explain the reading
 * within tau. The largest count of the surviving boxes (voxels) is then an upper bound on the
 * readings any pose explains within tau, and the connected sets of boxes (voxels) reaching it
 * hold every pose that may reach it. A region holding no returned candidate is excluded when a
 * finer subdivision of its boxes, tested with the adaptive engine's box test (conservative for
 * rays and cones), leaves none that may reach the bound.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Readings @p pose explains within @p tolerance [m]: its sensor in free space and
 *        |h - d| <= tolerance (h: predictedRange(), the ray or cone cast); a no-return reading
 *        when nothing lies nearer than max_range - tolerance.
 */
int consensusWithin(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings, double tolerance);

/**
 * @brief The adaptive engine's certificate: the bound is AdaptiveSearch::consensusBound(); the
 *        regions are the connected sets (26 neighbours, periodic theta) of leaves whose count
 *        reaches it, a candidate's region the one holding a leaf that contains its pose; the
 *        regions holding no candidate are excluded when subdividing their leaves three times
 *        (halving each axis) with the same box test leaves no box that may reach the bound.
 *        Incomplete whenever boxes set aside unresolved may reach the bound (a cut search).
 */
void certifyAdaptive(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance,
                     const AdaptiveSearch& search, std::int64_t theta_cells, Result& result);

/**
 * @brief The voxel engine's certificate: the bound is the count field's maximum (an upper bound
 *        where the voxel test is conservative); the regions are the connected sets of voxels
 *        reaching it, a candidate's region the one whose voxel box holds its pose; the others are
 *        excluded like the adaptive engine's, by the box test on subdivided voxel boxes.
 */
void certifyVoxels(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance,
                   const GridSpec& spec, const std::vector<std::uint8_t>& count, Result& result);

}  // namespace core
}  // namespace fdml_localization
