/**
 * @file ray_caster.h
 * @brief Exact nearest-hit ray casting against a set of segments through a uniform grid,
 *        and accelerated free-space queries on a polygon map.
 */
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// The nearest hit of a ray.
struct RayHit
{
  double distance = kInf;  ///< [m]; +inf when nothing is hit within the range
  int segment = -1;        ///< index of the segment hit, -1 on a miss
  bool hit() const
  {
    return segment >= 0;
  }
};

/**
 * @brief A uniform grid over segments. Each cell lists the segments that touch it; a ray
 *        walks the cells it crosses (Amanatides-Woo) and stops at the first cell whose own
 *        part of the ray holds a hit, so the cost grows with the cells crossed, not with the
 *        number of segments. Immutable after construction and safe to share between threads.
 */
class SegmentGrid
{
public:
  SegmentGrid() = default;
  /**
   * @param segments the segments to index
   * @param cell_size edge of a grid cell [m]; 0 chooses one from the segment count and extent
   */
  explicit SegmentGrid(std::vector<Segment> segments, double cell_size = 0.0);

  /// Nearest hit along origin + t dir, 0 <= t <= max_range. @p dir must be a unit vector.
  RayHit cast(const Vec2& origin, const Vec2& dir, double max_range = kInf) const;
  /// The same answer by a loop over every segment (reference for tests and benchmarks).
  RayHit castBruteForce(const Vec2& origin, const Vec2& dir, double max_range = kInf) const;

  /// True when some segment touches the closed box.
  bool anySegmentInBox(const Box2& box) const;
  /// Calls @p fn(index) once for every segment touching the box; stops early when fn returns false.
  void forEachSegmentInBox(const Box2& box, const std::function<bool(int)>& fn) const;

  /**
   * @brief Calls @p fn(cell, first, last) for every grid cell overlapping @p box: the cell's
   *        box [m] and the indices [first, last) of the segments touching it (a segment spans
   *        several cells, so it may be reported several times); stops when fn returns false.
   */
  template <typename Fn>
  void forEachCellInBox(const Box2& box, Fn&& fn) const
  {
    if (segments_.empty() || !box.intersects(bounds_))
    {
      return;
    }
    const int x1 = cellX(box.max.x());
    const int y1 = cellY(box.max.y());
    for (int cy = cellY(box.min.y()); cy <= y1; ++cy)
    {
      for (int cx = cellX(box.min.x()); cx <= x1; ++cx)
      {
        Box2 cell;
        cell.min = bounds_.min + Vec2(cx * cell_, cy * cell_);
        cell.max = cell.min + Vec2(cell_, cell_);
        const std::size_t c = static_cast<std::size_t>(cy) * nx_ + cx;
        if (!fn(cell, cell_items_.data() + cell_start_[c], cell_items_.data() + cell_start_[c + 1]))
        {
          return;
        }
      }
    }
  }

  /// Number of segments crossed by the horizontal half-line from p towards +x.
  int crossingsToRight(const Vec2& p) const;

  /**
   * @brief True when crossingsToRight(p) is odd, in time proportional to the segments of p's
   *        cell instead of its row: the parity stored for the cell's centre, flipped by every
   *        segment crossing the line from p to that centre (crossingsToRight where p lies on a
   *        segment's line or that line passes through a vertex, within 1e-9 of the cell size).
   */
  bool oddCrossingsToRight(const Vec2& p) const;

  const std::vector<Segment>& segments() const
  {
    return segments_;
  }
  const Box2& bounds() const
  {
    return bounds_;
  }
  double cellSize() const
  {
    return cell_;
  }

private:
  /// Fills the cells' compressed rows of segment indices.
  void buildCells();
  /// Fills centre_odd_: per cell, whether crossingsToRight of its centre is odd.
  void buildCentreParity();
  Vec2 cellCentre(int cx, int cy) const;
  /// Calls fn(cell index) for every cell the segment touches (cells inflated by a margin).
  template <typename Fn>
  void forEachCellTouching(const Segment& s, Fn&& fn) const;
  /// Clips origin + t dir to the grid's box: [t_enter, t_exit] narrowed; false when it misses.
  bool clipToBounds(const Vec2& origin, const Vec2& dir, double* t_enter, double* t_exit) const;
  /// Makes @p best the nearest of itself and the cell's segments hit (ties: the lower index).
  void castInCell(std::size_t cell, const Vec2& origin, const Vec2& dir, RayHit* best) const;
  /// Ray parameter at which origin + t dir leaves cell column/row @p c through its border on
  /// the @p step side along @p axis (+inf when dir is parallel to that border).
  double nextBorder(const Vec2& origin, const Vec2& dir, int axis, int c, int step) const;
  /// The column / row holding @p x / @p y, clamped to the grid (0 for NaN).
  int cellX(double x) const
  {
    return cellIndex((x - bounds_.min.x()) / cell_, nx_);
  }
  int cellY(double y) const
  {
    return cellIndex((y - bounds_.min.y()) / cell_, ny_);
  }
  /// floor(@p v) clamped to [0, n - 1] (n >= 1) without a call to floor (the casts' hot path).
  static int cellIndex(double v, int n)
  {
    if (!(v >= 0.0))
    {
      return 0;
    }
    return v >= n ? n - 1 : static_cast<int>(v);
  }

  std::vector<Segment> segments_;
  Box2 bounds_;
  double cell_ = 1.0;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<std::uint32_t> cell_start_;  ///< CSR offsets, size nx*ny+1
  std::vector<int> cell_items_;            ///< segment indices per cell
  std::vector<std::uint8_t> centre_odd_;   ///< per cell: crossingsToRight(cell centre) is odd
};

/**
 * @brief The static map prepared for queries: exact ray casts h(p) and free-space tests,
 *        both through a SegmentGrid over the map's edges.
 */
class MapRayCaster
{
public:
  MapRayCaster() = default;
  explicit MapRayCaster(PolygonMap map, double cell_size = 0.0);

  /// Distance from @p sensor along its +x axis to the first map edge [m], +inf on a miss
  /// (only possible from outside the map) or beyond @p max_range.
  double range(const Pose2& sensor, double max_range = kInf) const;
  RayHit cast(const Vec2& origin, const Vec2& dir, double max_range = kInf) const
  {
    return grid_.cast(origin, dir, max_range);
  }

  /// True when p is inside the outer ring and outside every hole. Each thread remembers its last
  /// point and verdict: the readings of one pose often share a sensor position (a rotating
  /// rangefinder), and their checks follow one another.
  bool isFree(const Vec2& p) const;

  const PolygonMap& map() const
  {
    return map_;
  }
  const SegmentGrid& grid() const
  {
    return grid_;
  }

private:
  PolygonMap map_;
  SegmentGrid grid_;
  /// Names this map's contents for isFree()'s memo (copies share it, as they share the contents).
  std::uint64_t id_ = 0;
};

}  // namespace core
}  // namespace fdml_localization
