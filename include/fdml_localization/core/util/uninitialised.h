/**
 * @file uninitialised.h
 * @brief A vector whose new elements are left uninitialised (default-initialised), for large
 *        arrays written in full right after they are sized: no serial zero fill, and each page
 *        is first touched by the thread that writes it.
 */
#pragma once

#include <memory>
#include <utility>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// std::allocator whose value-less construct() default-initialises (leaves a float as it is).
template <class T>
class UninitialisedAllocator : public std::allocator<T>
{
public:
  template <class U>
  struct rebind
  {
    using other = UninitialisedAllocator<U>;
  };

  UninitialisedAllocator() = default;
  template <class U>
  UninitialisedAllocator(const UninitialisedAllocator<U>& /*other*/) noexcept  // NOLINT: converting, as std::allocator
  {}

  template <class U>
  void construct(U* p) noexcept
  {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args)
  {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};

/// A vector of trivially constructible @p T whose resize() leaves the new elements uninitialised.
template <class T>
using UninitialisedVector = std::vector<T, UninitialisedAllocator<T>>;

}  // namespace core
}  // namespace fdml_localization
