/**
 * @file ring_sweep.h
 * @brief A sweep line (Shamos-Hoey) certifying in O(n log n) that rings are simple and
 *        disjoint: validateRings' fast path, whatever the shape (the edge grid degrades on
 *        rings whose edges zigzag densely).
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <algorithm>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// Sign of the turn a -> b -> c in extended precision (+1 left, -1 right, 0 collinear):
/// nearly collinear walls are common in maps converted from grids, where double rounding
/// gives wrong signs.
inline int orientExact(const Vec2& a, const Vec2& b, const Vec2& c)
{
  const long double v = (static_cast<long double>(b.x()) - a.x()) * (static_cast<long double>(c.y()) - a.y()) -
                        (static_cast<long double>(b.y()) - a.y()) * (static_cast<long double>(c.x()) - a.x());
  return (v > 0.0L) - (v < 0.0L);
}

/// True when p lies in the box spanned by a and b (closed).
inline bool inBox(const Vec2& a, const Vec2& b, const Vec2& p)
{
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) && p.y() >= std::min(a.y(), b.y()) &&
         p.y() <= std::max(a.y(), b.y());
}

/// True when the closed segments share a point (orientExact; the boxes must overlap too).
inline bool segmentsMeetExact(const Segment& s, const Segment& t)
{
  if (std::max(s.a.x(), s.b.x()) < std::min(t.a.x(), t.b.x()) ||
      std::max(t.a.x(), t.b.x()) < std::min(s.a.x(), s.b.x()) ||
      std::max(s.a.y(), s.b.y()) < std::min(t.a.y(), t.b.y()) ||
      std::max(t.a.y(), t.b.y()) < std::min(s.a.y(), s.b.y()))
  {
    return false;
  }
  const int o1 = orientExact(s.a, s.b, t.a);
  const int o2 = orientExact(s.a, s.b, t.b);
  const int o3 = orientExact(t.a, t.b, s.a);
  const int o4 = orientExact(t.a, t.b, s.b);
  if (o1 != o2 && o3 != o4)
  {
    return true;
  }
  return (o1 == 0 && inBox(s.a, s.b, t.a)) || (o2 == 0 && inBox(s.a, s.b, t.b)) || (o3 == 0 && inBox(t.a, t.b, s.a)) ||
         (o4 == 0 && inBox(t.a, t.b, s.b));
}

/**
 * @brief True when no two edges of the rings marked in @p usable meet, except consecutive
 *        edges of one ring at their shared vertex (and not folding back onto each other).
 *        False when some pair may meet: the caller then finds which, exactly. Rings must have
 *        at least 3 distinct consecutive vertices and finite coordinates.
 */
bool ringsDisjointBySweep(const std::vector<Ring>& rings, const std::vector<bool>& usable);

}  // namespace core
}  // namespace fdml_localization
