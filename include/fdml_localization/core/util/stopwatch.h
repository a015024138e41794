/**
 * @file stopwatch.h
 * @brief Wall-time measurement for the stage timings of results and benchmarks, and budgets.
 */
#pragma once

#include <chrono>

namespace fdml_localization
{
namespace core
{
/// Seconds of steady-clock time since @p start [s].
inline double secondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// A wall-time budget that starts when constructed; a budget of 0 (or less) never passes.
class Deadline
{
public:
  /// @param budget [s] from now; <= 0 = none
  explicit Deadline(double budget = 0.0) : start_(std::chrono::steady_clock::now()), budget_(budget)
  {}

  /// True once the budget is spent.
  bool passed() const
  {
    return budget_ > 0.0 && secondsSince(start_) > budget_;
  }

private:
  std::chrono::steady_clock::time_point start_;
  double budget_;
};

}  // namespace core
}  // namespace fdml_localization
