/**
 * @file ring_simplify.h
 * @brief Douglas-Peucker simplification of closed rings that keeps a set of rings valid
 *        (no self-intersections, no crossing or touching rings, holes inside the outer ring).
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Douglas-Peucker on a closed ring: every dropped vertex lies within @p tolerance [m]
 *        of the kept chain that replaces it. Exactly collinear vertices go even at tolerance 0.
 *        Rings of 3 vertices or fewer, and results under 3 vertices, come back unchanged.
 */
Ring simplifyRing(const Ring& ring, double tolerance);

/**
 * @brief Finds the rings that break validity: fewer than 3 vertices, zero area, a ring
 *        crossing or touching itself or another ring (a non-adjacent edge pair sharing a
 *        point, or adjacent edges folding back), or a hole (rings[1..]) outside rings[0] or
 *        inside another hole. Uses a bucket grid, so the cost grows with the edges, not their square.
 * @return one flag per ring: true when that ring takes part in a problem.
 */
std::vector<bool> findInvalidRings(const std::vector<Ring>& rings);

/// Results of simplifyRings().
struct SimplifyStats
{
  int rings_tightened = 0;  ///< rings that needed a smaller tolerance than asked
  bool valid = false;       ///< the returned rings pass findInvalidRings()
};

/**
 * @brief Simplifies every ring with @p tolerance [m]; while some rings are invalid together,
 *        halves the tolerance of the rings involved (down to 0 after a few halvings, where a
 *        ring is the input minus its collinear vertices). When the input rings are valid, so
 *        is the result.
 */
std::vector<Ring> simplifyRings(const std::vector<Ring>& rings, double tolerance, SimplifyStats* stats = nullptr);

}  // namespace core
}  // namespace fdml_localization
