/**
 * @file local_solve.h
 * @brief The robust solve restricted to a box of poses: the adaptive engine's conservative
 *        branch and prune over the box (no pose of the box that may explain k' readings is
 *        pruned), then the shared refinement (robust_search.h: refineSeed) from the best leaves.
 *        The tracker (hypothesis_tracker.h) runs it around each hypothesis's prediction.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/voxel/box_occupancy.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/// Settings of localSolve().
struct LocalSolveSettings
{
  int min_consensus = 6;              ///< k': net consensus a pose needs to count as a fix
  double cell_xy = 0.05;              ///< leaf size of the box search in x, y [m]
  double cell_theta = 0.025;          ///< ... and in theta [rad]
  double agreement_tolerance = 0.05;  ///< eps [m]
  double range_tolerance = 0.02;      ///< tau [m] (the box test's noise band)
  int max_seeds = 3;                  ///< distinct leaves refined (besides the box's centre)
  long max_boxes = 200000;            ///< box budget of the search
  /// Readings whose mounting headings lie within this [rad] count as one direction
  /// (LocalSolveOutcome::direction_loss). < 0 = no loss computed (zero).
  double direction_group = 0.25;
  /// The prediction and its information: every polish adds it (PosePrior, robust_search.h), so
  /// a fix stays at the prediction along directions the readings leave undetermined instead of
  /// sliding out of the box. Zero information = none.
  PosePrior prior;
};

/// The outcome of localSolve().
struct LocalSolveOutcome
{
  /// Refined poses inside the box (inflated by one leaf) with net consensus >= k', best first
  /// (ranking.h), duplicates (within 2 leaves) removed. Empty: the box holds no fix.
  std::vector<Candidate> fixes;
  /// For each fix, what its covariance gains when the readings of one direction are all wrong
  /// (oneDirectionLostCovariance(), robust_search.h) [m^2, rad^2].
  std::vector<Eigen::Matrix3d> direction_loss;
  /// The largest number of readings any leaf of the box may explain (0 when the search pruned
  /// every box at k'): an upper bound of the consensus inside the box when the search was not
  /// truncated.
  int best_possible = 0;
  /// The best net consensus reached by a refined pose in the box, or at the box's centre when
  /// the search pruned every box at k' (nothing refined).
  int best_consensus = 0;
  /// The fewest readings contradicted (longer than the map allows: no unknown obstacle explains
  /// them) at a refined pose, or at the box's centre when nothing was refined.
  int least_contradicted = 0;
  bool truncated = false;  ///< the box budget ran out
};

/**
 * @brief Finds the poses in @p box that explain at least settings.min_consensus readings (net of
 *        contradicted ones): a box search at that k' (AdaptiveSearchOptions::region), then
 *        refineSeed from the box's centre and from up to max_seeds distinct leaves of the highest
 *        counts. A refined pose that left the box (by more than one leaf) is not a fix.
 * @param occupancy the map's occupancy at a cell of at most settings.cell_xy
 */
LocalSolveOutcome localSolve(const MapRayCaster& map, const BoxOccupancy& occupancy,
                             const std::vector<Reading>& readings, const PoseBox& box,
                             const LocalSolveSettings& settings);

/**
 * @brief True when @p pose is provably the only place in @p region that may explain
 *        @p consensus of @p readings: no leaf of a conservative box search over the region (at
 *        most 128 leaves an axis, never finer than settings' cells) that may explain that many
 *        lies farther than @p distance [m] or @p angle [rad] from it by more than two leaves
 *        (the box test's looseness). False when the search ran out of its box budget
 *        (settings.max_boxes, as a local solve's: nothing proved, and the region of a hypothesis
 *        coasting for long costs no more).
 * @param occupancy the map's occupancy at a cell of at most settings.cell_xy
 */
bool onlyPlaceInRegion(const MapRayCaster& map, const BoxOccupancy& occupancy, const std::vector<Reading>& readings,
                       const PoseBox& region, const Pose2& pose, int consensus, double distance, double angle,
                       const LocalSolveSettings& settings);

/// True when @p pose lies in @p box inflated by @p margin_xy [m] and @p margin_theta [rad]
/// (theta compared modulo 2 pi).
bool insideBox(const Pose2& pose, const PoseBox& box, double margin_xy, double margin_theta);

}  // namespace core
}  // namespace fdml_localization
