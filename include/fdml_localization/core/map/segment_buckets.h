/**
 * @file segment_buckets.h
 * @brief A sparse uniform grid of segments for finding the pairs that may meet: cells the
 *        size of the mean segment, so that a segment passes through a few cells and a cell
 *        holds a few segments even where they crowd along walls. Used by validateRings.
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Every segment listed in the cells it passes through, with a one-cell margin across so
 *        that rounding never loses a contact: segments that share a point share a cell. Only
 *        occupied cells are stored (sorted keys). Building and querying all segments take
 *        O(n log n) for segments of similar lengths.
 */
class SegmentBuckets
{
public:
  /// @p segments must outlive this object and have finite coordinates.
  explicit SegmentBuckets(const std::vector<Segment>& segments);

  /// Calls visit(j) once for every segment j > i sharing a cell with segment i. Not reentrant.
  template <class Visit>
  void forEachLaterNeighbour(std::size_t i, Visit visit)
  {
    forEachRowSpan(segments_[i], [&](std::uint64_t first, std::uint64_t last) {
      // The occupied cells of the span are consecutive in keys_: one search per row.
      for (auto it = std::lower_bound(keys_.begin(), keys_.end(), first); it != keys_.end() && *it <= last; ++it)
      {
        const std::size_t cell = static_cast<std::size_t>(it - keys_.begin());
        for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k)
        {
          const std::size_t j = items_[k];
          if (j > i && stamp_[j] != i + 1)
          {
            stamp_[j] = i + 1;
            visit(j);
          }
        }
      }
    });
  }

private:
  static constexpr double kMaxCells = 1073741824.0;  ///< per side: 2^30, so a key fits 64 bits

  std::uint64_t index(double value, double origin) const
  {
    const double f = std::floor((value - origin) / cell_);
    return static_cast<std::uint64_t>(std::clamp(f, 0.0, kMaxCells));
  }

  /// Calls span(first, last) with the keys (row << 32 | column) of the first and last cell of
  /// every row segment @p s passes through.
  template <class Span>
  void forEachRowSpan(const Segment& s, Span span) const
  {
    const std::uint64_t r0 = index(std::min(s.a.y(), s.b.y()), origin_.y());
    const std::uint64_t r1 = index(std::max(s.a.y(), s.b.y()), origin_.y());
    const double dy = s.b.y() - s.a.y();
    const double dx = s.b.x() - s.a.x();
    for (std::uint64_t r = r0; r <= r1; ++r)
    {
      double x0 = std::min(s.a.x(), s.b.x());
      double x1 = std::max(s.a.x(), s.b.x());
      if (r0 != r1)
      {
        // The part of the segment within this row (dy != 0 since it spans rows).
        const double ylo = origin_.y() + static_cast<double>(r) * cell_;
        const double t0 = std::clamp((ylo - s.a.y()) / dy, 0.0, 1.0);
        const double t1 = std::clamp((ylo + cell_ - s.a.y()) / dy, 0.0, 1.0);
        x0 = std::min(s.a.x() + t0 * dx, s.a.x() + t1 * dx);
        x1 = std::max(s.a.x() + t0 * dx, s.a.x() + t1 * dx);
      }
      const std::uint64_t c0 = index(x0, origin_.x());
      span((r << 32) | (c0 == 0 ? 0 : c0 - 1), (r << 32) | (index(x1, origin_.x()) + 1));
    }
  }

  const std::vector<Segment>& segments_;
  std::vector<std::size_t> stamp_;
  std::vector<std::uint64_t> keys_;   ///< occupied cells, sorted
  std::vector<std::uint32_t> start_;  ///< items of keys_[k]: items_[start_[k] .. start_[k + 1])
  std::vector<std::uint32_t> items_;
  Vec2 origin_;
  double cell_ = 1.0;
};

}  // namespace core
}  // namespace fdml_localization
