/**
 * @file threads.h
 * @brief The one reading of a thread-count option (LocalizerOptions::threads and the tools'
 *        --threads): the number of OpenMP threads a parallel region of the core runs with.
 */
#pragma once

#include <omp.h>

namespace fdml_localization
{
namespace core
{
/// The OpenMP threads for @p requested: itself when positive, else all cores (0 = all).
inline int threadsFor(int requested)
{
  return requested > 0 ? requested : omp_get_max_threads();
}

}  // namespace core
}  // namespace fdml_localization
