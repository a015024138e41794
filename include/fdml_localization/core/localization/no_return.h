/**
 * @file no_return.h
 * @brief Readings with no return (range = +inf) under LocalizerOptions::no_return.
 *
 * - constraint (the default): a no-return agrees only where the map has no wall within
 *   max_range (within the agreement tolerance), and contradicts a pose where it has: right for
 *   a sensor whose no-return means "free up to max_range" (a ToF or ultrasonic ranger).
 * - weak: the search uses the readings with a return only (k' counts them only); at each
 *   candidate a no-return is neither an inlier nor contradicted, and candidates tied on net
 *   consensus and contradicted readings are ordered by how many no-returns agree before RMS:
 *   right for a lidar that reports no echo on glass or dark surfaces with a wall in range.
 * - drop: no-returns are removed before the search: the same lidar, when ties do not matter.
 * Under weak and drop, Result::readings_used counts the readings with a return, and inlier
 * masks have one entry per reading given (false for every no-return).
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"

#include <cstddef>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief The readings with a return (finite range), and their indices in @p readings.
 * @throws InvalidInput when fewer than 3 have a return, or fewer than a fixed k'
 *         (options.min_inliers), naming the count and options.no_return.
 */
std::vector<Reading> readingsWithReturn(const std::vector<Reading>& readings, const LocalizerOptions& options,
                                        std::vector<std::size_t>* kept);

/**
 * @brief Maps a result found on readingsWithReturn() back onto every reading: inlier masks get
 *        one entry per reading (false for a no-return); under NoReturnPolicy::Weak, candidates
 *        tied on net consensus and contradicted readings are reordered by the no-returns that
 *        agree at their pose (as under constraint), most first, then by RMS.
 */
void restoreNoReturns(Result* result, const std::vector<Reading>& readings, const std::vector<std::size_t>& kept,
                      const LocalizerOptions& options, const MapRayCaster& map);

}  // namespace core
}  // namespace fdml_localization
