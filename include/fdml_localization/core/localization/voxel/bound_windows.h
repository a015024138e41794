/**
 * @file bound_windows.h
 * @brief The cell bounds (cell_bounds.h) combined over the windows of cells a voxel's sensor
 *        poses can cover: 2 x 2 cells in position and m cells in heading (periodic), for rays
 *        and for cone readings (sliding minima over the heading window). Computed on demand
 *        once per window length and kept in memory.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/cell_bounds.h"
#include "fdml_localization/core/localization/voxel/range_steps.h"
#include "fdml_localization/core/util/uninitialised.h"

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace fdml_localization
{
namespace core
{
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
