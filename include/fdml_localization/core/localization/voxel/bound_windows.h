/**
 * @file bound_windows.h
 * @brief The cell bounds (cell_bounds.h) combined over the windows of cells a voxel's sensor
 *        poses can cover: 2 x 2 cells in position and m cells in heading (periodic), for rays
 *        and for cone readings (sliding minima over the heading window). Computed on demand
 *        once per window length and kept in memory.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/cell_bounds.h"
#include "fdml_localization/core/util/uninitialised.h"

#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Ranges [m] in 16-bit steps of unit metres, rounded so that each comparison of the
 *        preimage test keeps its outcome or becomes true (the test stays conservative): lower
 *        bounds and the top of a reading's band rounded down, upper bounds and the bottom of the
 *        band rounded up. Both roundings are monotone, so they commute with the minima and
 *        maxima over the windows. Values beyond the last step take it; NaN takes the end that
 *        keeps a voxel.
 */
struct RangeSteps
{
  static constexpr std::uint16_t kLast = 65535;
  double unit = 1e-3;  ///< [m]

  /// For the bounds up to @p farthest [m] (the largest finite one): steps of about 1 / 65000 of
  /// it, at least 0.1 mm.
  static RangeSteps covering(double farthest);

  std::uint16_t down(double value) const
  {
    const double q = std::floor(value / unit);
    return !(q > 0.0) ? 0 : q >= kLast ? kLast : static_cast<std::uint16_t>(q);
  }
  std::uint16_t up(double value) const
  {
    const double q = std::ceil(value / unit);
    return !(q < kLast) ? kLast : q <= 0.0 ? 0 : static_cast<std::uint16_t>(q);
  }
};

/**
 * Arrays shaped like the voxel grid: entry (wx, wy, jt) covers the cells jx in {wx - 1, wx},
 * jy in {wy - 1, wy} and the m heading cells jt .. jt + m - 1.
 */
class BoundWindows
{
public:
  enum class Kind
  {
    Lower,       ///< min of the lower bounds over the window
    UpperMax,    ///< max of the upper bounds over the window
    UpperInner,  ///< max over the 2 x 2 positions of the min over the m headings of the upper bounds
  };

  BoundWindows() = default;
  explicit BoundWindows(CellBounds cells);

  const CellBounds& cells() const
  {
    return cells_;
  }
  /// Computes the array unless it is already there (not thread-safe: call before parallel reads).
  void require(Kind kind, int m);
  /// A required array, in steps() (throws std::logic_error when it was not required).
  const UninitialisedVector<std::uint16_t>& get(Kind kind, int m) const;
  /// The steps of the arrays.
  const RangeSteps& steps() const
  {
    return steps_;
  }
  std::size_t memoryBytes() const;

private:
  CellBounds cells_;
  RangeSteps steps_;
  std::map<std::pair<int, int>, UninitialisedVector<std::uint16_t>> arrays_;
  UninitialisedVector<float> along_;  ///< require()'s scratch: the bounds over the heading window
};

}  // namespace core
}  // namespace fdml_localization
