/**
 * @file range_steps.h
 * @brief Ranges [m] as 16-bit steps for the voxel engine's preimage tests (bound windows and
 *        the sample table's blocks): half the bytes of floats to stream per voxel.
 */
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Ranges [m] in 16-bit steps of unit metres, rounded so that each comparison of a
 *        preimage test keeps its outcome or becomes true: lower bounds and the top of a
 *        reading's band rounded down (down()), upper bounds and the bottom of the band rounded
 *        up (up()). Both are monotone, so they commute with minima and maxima. The infinite
 *        ends keep steps of their own (down: finite values at most kLast - 1, +inf kLast; up:
 *        finite values at least 1, -inf 0), so a bound of +inf or -inf still fails against any
 *        finite band as it did; NaN takes the end that keeps a voxel.
 */
struct RangeSteps
{
  static constexpr std::uint16_t kLast = 65535;
  double unit = 1e-3;  ///< [m]

  /// For values up to @p farthest [m] (the largest finite one): steps of about 1 / 65000 of
  /// it, at least 0.1 mm.
  static RangeSteps covering(double farthest)
  {
    RangeSteps steps;
    steps.unit = std::max(1e-4, std::isfinite(farthest) ? farthest / 65000.0 : 1e-4);
    return steps;
  }

  /// covering() the largest finite value of @p arrays [m] (infinities and NaN ignored).
  static RangeSteps covering(std::initializer_list<const std::vector<float>*> arrays)
  {
    double farthest = 0.0;
    for (const std::vector<float>* values : arrays)
    {
      for (float x : *values)
      {
        farthest = std::isfinite(x) ? std::max(farthest, static_cast<double>(x)) : farthest;
      }
    }
    return covering(farthest);
  }

  std::uint16_t down(double value) const
  {
    if (value == std::numeric_limits<double>::infinity())
    {
      return kLast;
    }
    const double q = std::floor(value / unit);
    return !(q > 0.0) ? 0 : q >= kLast - 1 ? kLast - 1 : static_cast<std::uint16_t>(q);
  }
  std::uint16_t up(double value) const
  {
    if (value == -std::numeric_limits<double>::infinity())
    {
      return 0;
    }
    const double q = std::ceil(value / unit);
    return !(q < kLast) ? kLast : q <= 1.0 ? 1 : static_cast<std::uint16_t>(q);
  }
};

}  // namespace core
}  // namespace fdml_localization
