/**
 * @file continuum_gain.h
 * @brief A candidate on a continuum of poses (a corridor: its readings agree all along it) moved
 *        to where it explains more readings: a reading its inliers leave out may be explained on
 *        a short stretch of the continuum only (a side sensor passing a door frame), which the
 *        polish, blind to what it does not use, never reaches. Used by settleAlongContinua().
 */
#pragma once

#include "fdml_localization/core/localization/robust_search.h"

#include <Eigen/Core>

#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief The pose on the translation continuum of @p candidate (its heading kept) explaining more
 *        readings (net consensus) than it, polished; or @p candidate where none does.
 *
 * Along @p direction, from @p behind [m] behind the candidate to @p ahead [m] ahead of it, a
 * reading outside the candidate's inliers changes what it explains only where its ray passes a
 * map vertex within its max range (what it hits jumps: a wall's end) or where its residual
 * changes sign (bisected to 1/2^24 of the stretch). Every stretch between such offsets is tried
 * at its middle and every sign change at itself; the pose explaining the most readings wins,
 * then the longer stretch. It is polished (polishedFrom(), settings' eps and noise_sigma) when
 * that ranks it before (betterCandidate()), and carries a covariance either way. Cone readings
 * (half_angle > 0) are left out of the offsets.
 * @param direction unit translation (x, y) along which the candidate's readings keep agreeing
 * @param behind, ahead how far they keep agreeing each way [m], both >= 0
 */
Candidate gainAlongContinuum(const MapRayCaster& map, const std::vector<Reading>& readings,
                             const RefinementSettings& settings, const Candidate& candidate,
                             const Eigen::Vector2d& direction, double behind, double ahead);

}  // namespace core
}  // namespace fdml_localization
