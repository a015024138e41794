/**
 * @file ring_validation_reference.h
 * @brief The verdict of the previous validateRings (Boost.Geometry's is_valid on each ring,
 *        then on the whole polygon): the reference the grid-based validateRings is tested and
 *        benchmarked against. Quadratic on large rings; for small test rings only.
 */
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

// Boost 1.74's rescale policy trips GCC 12's -Wmaybe-uninitialized (a false positive inside
// Boost, get_rescale_policy.hpp): silenced for these headers only.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace test
{
using BgPoint = boost::geometry::model::d2::point_xy<double>;
/// Counter-clockwise outer ring, clockwise holes, open rings: PolygonMap's conventions.
using BgPolygon = boost::geometry::model::polygon<BgPoint, false, false>;

inline Ring orientedRing(const Ring& ring, bool counter_clockwise)
{
  Ring out = ring;
  if ((signedArea(out) > 0.0) != counter_clockwise)
  {
    std::reverse(out.begin(), out.end());
  }
  return out;
}

inline void appendRing(const Ring& ring, std::vector<BgPoint>& out)
{
  for (const Vec2& v : ring)
  {
    out.emplace_back(v.x(), v.y());
  }
}

/// The old verdict: -1 when valid, else the index of the first ring found invalid on its own,
/// or rings.size() when only the rings together are invalid.
inline long referenceVerdict(const std::vector<Ring>& rings)
{
  std::vector<Ring> clean;
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    for (const Vec2& v : rings[r])
    {
      if (!v.allFinite())
      {
        return static_cast<long>(r);
      }
    }
    clean.push_back(orientedRing(cleanRing(rings[r]), r == 0));
    BgPolygon alone;
    appendRing(orientedRing(clean.back(), true), alone.outer());
    if (clean.back().size() < 3 || !boost::geometry::is_valid(alone))
    {
      return static_cast<long>(r);
    }
  }
  BgPolygon whole;
  appendRing(clean[0], whole.outer());
  for (std::size_t r = 1; r < clean.size(); ++r)
  {
    whole.inners().emplace_back();
    appendRing(clean[r], whole.inners().back());
  }
  return boost::geometry::is_valid(whole) ? -1 : static_cast<long>(rings.size());
}

}  // namespace test
}  // namespace core
}  // namespace fdml_localization
