/**
 * @file adaptive_search.h
 * @brief Branch and prune over boxes of poses in R^2 x S^1 (the adaptive engine's search).
 *
 * For a pose box B = [x0,x1] x [y0,y1] x [t0,t1] and a reading (g, d), every hit point
 * (x, y) + R(theta) v, v = (gx + d cos g_theta, gy + d sin g_theta), lies in the exact bounding
 * box of the arc R(theta) v over [t0, t1] plus [x0,x1] x [y0,y1], inflated by the range
 * tolerance. When no map edge meets that box, the reading cannot be explained anywhere in B.
 * A cone reading of half-angle a (the nearest map point within a sector) has its hit point at
 * distance d in some direction of the sector: the heading interval of the direction's arc is
 * widened by a on each side (hitArcBounds()), which keeps the test conservative.
 * A box survives while at least k' readings may be explained, so the box holding the truth is
 * never pruned (no exceptions near discontinuities of h), and the work grows with the answer.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/box_occupancy.h"
#include "fdml_localization/core/localization/localizer.h"

#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
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

  Pose2 centre() const
  {
    return Pose2(0.5 * (x0 + x1), 0.5 * (y0 + y1), wrapAngle(0.5 * (t0 + t1)));
  }

  /// True when @p q lies in the box grown by @p margin [m] in x, y and @p angle [rad] in theta
  /// (theta periodic).
  bool contains(const Pose2& q, double margin = 0.0, double angle = 0.0) const
  {
    const double t = t0 + std::remainder(q.theta - t0, kTwoPi);
    const auto within = [&](double a) { return a >= t0 - angle && a <= t1 + angle; };
    return q.x >= x0 - margin && q.x <= x1 + margin && q.y >= y0 - margin && q.y <= y1 + margin &&
           (within(t) || within(t + kTwoPi) || within(t - kTwoPi));
  }

  /// The @p c-th (0 to 7) of the 8 boxes every axis halved gives: bit 0 set for the upper half
  /// in x, bit 1 in y, bit 2 in theta.
  PoseBox half(int c) const
  {
    PoseBox h = *this;
    ((c & 1) ? h.x0 : h.x1) = 0.5 * (x0 + x1);
    ((c & 2) ? h.y0 : h.y1) = 0.5 * (y0 + y1);
    ((c & 4) ? h.t0 : h.t1) = 0.5 * (t0 + t1);
    return h;
  }
};

/// A surviving leaf box, with the number of readings that may be explained in it.
struct LeafBox
{
  PoseBox box;
  int count = 0;                        ///< readings that pass the box test
  std::uint64_t mask = 0;               ///< bit i set when reading i passes (first 64 readings)
  std::int64_t ix = 0, iy = 0, it = 0;  ///< integer cell of the leaf at the finest level
};

/// Options of the box search.
struct AdaptiveSearchOptions
{
  double cell_xy = 0.05;          ///< leaf size in x and y [m]
  double cell_theta = 0.05;       ///< leaf size in theta [rad]
  int min_count = 3;              ///< k': a box needs this many explainable readings
  double range_tolerance = 0.02;  ///< tau [m]
  long max_boxes = 20000000;      ///< budget of boxes tested over the whole search
  double deadline = 0.0;          ///< wall-time budget [s]; 0 = none
  int threads = 0;                ///< OpenMP threads; 0 = all
  /// Lowest k' a resumed search may be asked for (AdaptiveSearch::run); boxes pruned with an
  /// upper bound of at least this many readings are kept aside for a later, lower k'.
  int floor_count = 0;
  /// Levels with at most this many boxes are tested on one thread (no barrier cost).
  long parallel_threshold = 2000;
  /// The pose box the root grid covers (a local search, e.g. around a tracked pose); unset =
  /// the map's bounding box x [-pi, pi). Its theta span is clamped to 2 pi.
  std::optional<PoseBox> region;
  /// Where the robot's base may be (LocalizerOptions::search_region): boxes whose positions
  /// lie wholly outside it are pruned. Null = anywhere in free space. Must outlive the search.
  const BoxOccupancy* positions = nullptr;
};

/// The outcome of a box search.
struct AdaptiveSearchResult
{
  std::vector<LeafBox> leaves;        ///< surviving boxes at the finest level
  std::vector<long> boxes_per_level;  ///< boxes kept at each level (level 0 = the root grid)
  long boxes_tested = 0;
  bool truncated = false;  ///< a budget was reached; leaves are from the last full level
};

/// The conservative per-reading box test (exposed for tests): false only when the reading
/// provably cannot be explained by any pose in @p box: the sensor outside free space, no map
/// edge where the reading ends (within @p range_tolerance [m]), or an edge nearer in every pose's
/// ray or cone (docs/METHOD.md, the adaptive engine and cone readings).
bool readingMayExplain(const MapRayCaster& map, const Reading& reading, const PoseBox& box, double range_tolerance);

/**
 * @brief How many of @p readings some pose in @p box may explain (readingMayExplain() per
 *        reading, 0 when the robot's base is outside free space everywhere in the box), counted
 *        only until it is clear whether @p needed is reached: a result below @p needed proves
 *        that no pose in the box explains @p needed readings.
 */
int boxConsensusBound(const MapRayCaster& map, const std::vector<Reading>& readings, double range_tolerance,
                      const PoseBox& box, int needed);

/**
 * @brief boxConsensusBound() over a run of nearby boxes (the sub-boxes of one leaf): a reading
 *        that rules a box out is tested first for the next box, mostly ruled out by the same
 *        reading. The same answers in fewer reading tests: where 28 of 30 readings are
 *        no-returns, most boxes pass those and fail on one of the two returns (screening 12,222
 *        leaves took a third less time).
 */
class BoxConsensusTest
{
public:
  /// @p map and @p readings must outlive the test; @p range_tolerance [m] as in readingMayExplain().
  BoxConsensusTest(const MapRayCaster& map, const std::vector<Reading>& readings, double range_tolerance);

  /// boxConsensusBound() of @p box, its readings in this test's order (the same count whenever it
  /// reaches @p needed).
  int bound(const PoseBox& box, int needed);

  /// True when some pose in @p box may explain @p needed readings (bound() >= @p needed).
  bool reaches(const PoseBox& box, int needed)
  {
    return bound(box, needed) >= needed;
  }

private:
  /// Reading @p r's arcs over @p box's headings, kept while the heading interval stays the same:
  /// the boxes of one heading slice (a voxel grid's theta row) share them, and their
  /// trigonometry was half of the test's time (AdaptiveSearch keeps its own per-level table).
  void ensureArcs(std::size_t r, const PoseBox& box);

  const MapRayCaster& map_;
  const std::vector<Reading>& readings_;
  double range_tolerance_;
  std::vector<std::size_t> order_;  ///< reading indices in the order they are tested
  /// The heading interval [rad] the arcs below are for.
  double arcs_t0_ = std::numeric_limits<double>::quiet_NaN();
  double arcs_t1_ = std::numeric_limits<double>::quiet_NaN();
  std::vector<Box2> sensor_arcs_;  ///< per reading: rotatedArcBounds() of its sensor's offset
  std::vector<Box2> hit_arcs_;     ///< per reading: hitArcBounds()
  std::vector<char> have_arcs_;    ///< per reading: the two arcs are for [arcs_t0_, arcs_t1_]
};

/// Exact bounding box of the arc R(theta) v for theta in [t0, t1] (t1 - t0 <= 2 pi).
Box2 rotatedArcBounds(const Vec2& v, double t0, double t1);

/**
 * @brief A box holding every hit point of @p reading relative to the robot's position, for every
 *        robot heading in [t0, t1] [rad] (empty for a no-return reading). A ray (half_angle 0):
 *        the exact bounds of the arc R(theta) v, v = (gx + d cos g_theta, gy + d sin g_theta).
 *        A cone of half-angle a: the hit point is the sensor position R(theta) (gx, gy) plus d in
 *        a direction within [theta + g_theta - a, theta + g_theta + a], so the sum of the bounds
 *        of the sensor's arc over [t0, t1] and of the arc of d (cos g_theta, sin g_theta) over
 *        [t0 - a, t1 + a].
 */
Box2 hitArcBounds(const Reading& reading, double t0, double t1);

/// Runs the search over the map's bounding box x [-pi, pi).
AdaptiveSearchResult adaptiveSearch(const MapRayCaster& map, const std::vector<Reading>& readings,
                                    const AdaptiveSearchOptions& options);

/// The same search with a prebuilt occupancy grid of the map (see AdaptiveSearch).
AdaptiveSearchResult adaptiveSearch(const MapRayCaster& map, const BoxOccupancy& occupancy,
                                    const std::vector<Reading>& readings, const AdaptiveSearchOptions& options);

/**
 * @brief A resumable search for maximum consensus: run(k1) keeps the leaves with at least k1
 *        explainable readings; a later run(k2), k2 < k1, adds exactly the leaves with k2 <= count
 *        < k1 by resuming from the boxes the earlier runs set aside (never testing a box twice at
 *        the same k'), so lowering k' step by step costs one search, not one per step.
 */
class AdaptiveSearch
{
public:
  /// @p occupancy and @p map must outlive the search; options.floor_count bounds later run()s.
  AdaptiveSearch(const MapRayCaster& map, const BoxOccupancy& occupancy, std::vector<Reading> readings,
                 const AdaptiveSearchOptions& options);

  /// Searches down to the leaves for k' = @p min_count (>= options.floor_count, not above the
  /// previous run's) and returns all leaves found so far, with counts >= min_count.
  const AdaptiveSearchResult& run(int min_count);
  const AdaptiveSearchResult& result() const
  {
    return result_;
  }

  /**
   * @brief An upper bound on the readings any pose of the searched space explains within the
   *        range tolerance: the largest count of the leaves and of the boxes set aside (their
   *        counts are upper bounds), and floor_count - 1 for the boxes pruned.
   */
  int consensusBound() const;

  /// True when a box set aside unresolved (by a budget, or below every k' run) may reach @p count.
  bool unresolvedReaches(int count) const;

private:
  struct Node
  {
    std::int32_t ix, iy, it;  ///< index of the node's first leaf cell along each axis
    std::int32_t count;       ///< readings that pass (an upper bound for set-aside nodes)
    std::uint64_t mask;
  };
  PoseBox boxOf(const Node& n, int level) const;
  /// Tests one node against @p min_count; fills count (exact when kept) and mask.
  bool test(Node& n, int level, int min_count) const;
  void prepareArcs(int level);
  /// Moves the set-aside boxes of @p level that may reach @p min_count into @p current, within
  /// the box budget; true when the budget cut them.
  bool resumeSetAside(int level, int min_count, std::vector<Node>& current);
  /// Tests @p current: the kept boxes go to @p survivors, those that may reach floor_count aside.
  void testLevel(int level, int min_count, std::vector<Node>& current, std::vector<Node>& survivors);
  void addLeaves(const std::vector<Node>& survivors, int level);
  /// The children of @p survivors at the next level (halving the axes not yet at leaf size).
  void split(const std::vector<Node>& survivors, int level, std::vector<Node>& children) const;

  const MapRayCaster& map_;
  const BoxOccupancy& occupancy_;
  std::vector<Reading> readings_;
  AdaptiveSearchOptions options_;
  PoseBox root_;  ///< the box the root grid covers (options.region or the whole map)
  std::int64_t nx_ = 1, ny_ = 1, nt_ = 1;
  double cell_t_ = 1.0;
  int lx_ = 0, ly_ = 0, lt_ = 0, levels_ = 0;
  std::vector<std::vector<Node>> set_aside_;  ///< per level
  std::vector<std::vector<Box2>> arcs_;       ///< per level: [theta node * readings * 2] hit / sensor arcs
  AdaptiveSearchResult result_;
  bool started_ = false;
  bool finished_ = false;  ///< a budget cut the search; no more runs
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
  double elapsed_ = 0.0;
};

}  // namespace core
}  // namespace fdml_localization
