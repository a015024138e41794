// Shared by the grid tests: a reproducible uniform draw and a small office floor plan.
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

#include <random>
#include <vector>

namespace grid_test
{
namespace core = fdml_localization::core;

/// Uniform in [0, 1) from a 64-bit engine (the same on every standard library).
inline double uniform(std::mt19937_64& rng)
{
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}

/// A 12 x 8 m office: two wall stubs off the outer wall, a pillar, a desk block, a partition
/// and a rotated square column.
inline core::PolygonMap officeMap()
{
  std::vector<core::Ring> rings = {
    { { 0, 0 },
      { 12, 0 },
      { 12, 8 },
      { 7.1, 8 },
      { 7.1, 5 },
      { 6.9, 5 },
      { 6.9, 8 },
      { 0, 8 },
      { 0, 4.1 },
      { 3, 4.1 },
      { 3, 3.9 },
      { 0, 3.9 } },
    { { 5, 1.5 }, { 5.3, 1.5 }, { 5.3, 1.8 }, { 5, 1.8 } },
    { { 9, 2 }, { 11, 2 }, { 11, 3 }, { 9, 3 } },
    { { 9, 5.5 }, { 9.2, 5.5 }, { 9.2, 7 }, { 9, 7 } },
    { { 2, 6 }, { 2.4, 6.3 }, { 2, 6.6 }, { 1.6, 6.3 } },
  };
  return core::PolygonMap::fromRings(rings, "office");
}
}  // namespace grid_test
