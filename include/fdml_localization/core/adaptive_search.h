/**
 * @file adaptive_search.h
 * @brief Branch and prune over boxes of poses in R^2 x S^1 (the adaptive engine's search).
 *
 * For a pose box B = [x0,x1] x [y0,y1] x [t0,t1] and a reading (g, d), every hit point
 * (x, y) + R(theta) v, v = (gx + d cos g_theta, gy + d sin g_theta), lies in the exact bounding
 * box of the arc R(theta) v over [t0, t1] plus [x0,x1] x [y0,y1], inflated by the range
 * tolerance. When no map edge meets that box, the reading cannot be explained anywhere in B.
 * A box survives while at least k' readings may be explained, so the box holding the truth is
 * never pruned (no exceptions near discontinuities of h), and the work grows with the answer.
 */
#pragma once

#include "fdml_localization/core/localizer.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A box of poses [m], [rad]. theta may extend past +-pi; it is periodic.
struct PoseBox
{
  double x0 = 0.0, x1 = 0.0;
  double y0 = 0.0, y1 = 0.0;
  double t0 = 0.0, t1 = 0.0;

  Pose2 centre() const { return Pose2(0.5 * (x0 + x1), 0.5 * (y0 + y1), wrapAngle(0.5 * (t0 + t1))); }
};

/// A surviving leaf box, with the number of readings that may be explained in it.
struct LeafBox
{
  PoseBox box;
  int count = 0;              ///< readings that pass the box test
  std::uint64_t mask = 0;     ///< bit i set when reading i passes (first 64 readings)
  std::int64_t ix = 0, iy = 0, it = 0;  ///< integer cell of the leaf at the finest level
};

/// Options of the box search.
struct AdaptiveSearchOptions
{
  double cell_xy = 0.05;       ///< leaf size in x and y [m]
  double cell_theta = 0.05;    ///< leaf size in theta [rad]
  int min_count = 3;           ///< k': a box needs this many explainable readings
  double range_tolerance = 0.02;  ///< tau [m]
  long max_boxes = 20000000;   ///< budget of boxes tested over the whole search
  double deadline = 0.0;       ///< wall-time budget [s]; 0 = none
  int threads = 0;             ///< OpenMP threads; 0 = all
};

/// The outcome of a box search.
struct AdaptiveSearchResult
{
  std::vector<LeafBox> leaves;          ///< surviving boxes at the finest level
  std::vector<long> boxes_per_level;    ///< boxes kept at each level (level 0 = the root grid)
  long boxes_tested = 0;
  bool truncated = false;               ///< a budget was reached; leaves are from the last full level
};

/// The conservative per-reading box test (exposed for tests): false only when the reading
/// provably cannot be explained by any pose in @p box.
bool readingMayExplain(const MapRayCaster& map, const Reading& reading, const PoseBox& box, double range_tolerance);

/// Exact bounding box of the arc R(theta) v for theta in [t0, t1] (t1 - t0 <= 2 pi).
Box2 rotatedArcBounds(const Vec2& v, double t0, double t1);

/// Runs the search over the map's bounding box x [-pi, pi).
AdaptiveSearchResult adaptiveSearch(const MapRayCaster& map, const std::vector<Reading>& readings,
                                    const AdaptiveSearchOptions& options);

}  // namespace core
}  // namespace fdml_localization
