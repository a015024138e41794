/**
 * @file region_starts.h
 * @brief The seeds' agreement gate, and where to start refinements inside a region of the
 *        search (a plateau of voxels or leaves): the region's poses that agree best with the
 *        readings. A large region (few finite readings constrain it) can hold several distinct
 *        optima, and its centroid can lie far from all of them.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <cstddef>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// The scale of an engine's seeds: how far a seed may lie from the optimum.
struct SeedScale
{
  double cell_xy = 0.1;     ///< cell or leaf size [m]
  double cell_theta = 0.1;  ///< cell or leaf size [rad]
};

/// The median of the readings' finite ranges [m]; 1 m when none is finite.
double medianFiniteRange(const std::vector<Reading>& readings);

/**
 * @brief The loose agreement band [m] at a seed's start: 3 x the robust scale of the first
 *        polish, max(eps, half a cell + half a cell's angle x the median finite range). Seeds
 *        where fewer than level - 2 readings agree within it are not refined; engines use it to
 *        pick their best starts.
 */
double seedGate(const std::vector<Reading>& readings, const LocalizerOptions& options, const SeedScale& scale);

/// How far into free space freeStart() moves a start off a wall [m].
constexpr double kOffWall = 1e-3;

/**
 * @brief @p start, or when its position is not free (a cell's centre inside a wall, while the
 *        cell holds a sliver of free space along it), the free point nearest to it among the
 *        points kOffWall off the walls within @p reach [m] of it (each wall's point nearest the
 *        start, moved to its free side); @p start when there is none. A polish started inside a
 *        wall sees no gradient.
 */
Pose2 freeStart(const MapRayCaster& map, const Pose2& start, double reach);

/**
 * @brief How badly @p pose agrees with @p readings: the sum over readings of r^2 where the
 *        reading agrees within @p gate [m] (|r| < gate; 0 for a no-return reading nothing in
 *        range contradicts) and gate^2 where it does not or the sensor is not in free space
 *        [m^2]; the verdicts and residuals of evaluatePose(), with casts cut at d + gate.
 */
double agreementScore(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings, double gate);

/**
 * @brief Of @p poses (of at most @p sampled of them spread over the list), those agreeing best
 *        with @p readings (fewest readings off by more than @p gate [m], then the smallest sum of
 *        squared residuals), each moved off a wall first (freeStart(), within half
 *        @p separation_xy), at most @p max_poses, pairwise apart by more than @p separation_xy
 *        [m] or @p separation_theta [rad]; best first.
 */
std::vector<Pose2> bestAgreeingPoses(const MapRayCaster& map, const std::vector<Pose2>& poses,
                                     const std::vector<Reading>& readings, double gate, double separation_xy,
                                     double separation_theta, std::size_t max_poses, std::size_t sampled);

}  // namespace core
}  // namespace fdml_localization
