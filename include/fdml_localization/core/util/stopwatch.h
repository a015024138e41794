/**
 * @file stopwatch.h
 * @brief Wall-time measurement for the stage timings of results and benchmarks.
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

}  // namespace core
}  // namespace fdml_localization
