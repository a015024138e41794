/**
 * @file polygon_map.h
 * @brief The known static workspace W: a polygon with holes [m].
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A problem found while validating rings: which ring and vertex, and why.
struct RingIssue
{
  std::size_t ring = 0;    ///< ring index (0 = outer boundary)
  std::size_t vertex = 0;  ///< vertex index within the ring
  std::string reason;
};

/// Thrown for an invalid map. what() is "FILE:LINE: reason" when a file and line are known.
class MapError : public std::runtime_error
{
public:
  MapError(const std::string& file, int line, const std::string& reason);
  const std::string& file() const
  {
    return file_;
  }
  int line() const
  {
    return line_;
  }  ///< 1-based line, 0 when not tied to a line
  const std::string& reason() const
  {
    return reason_;
  }

private:
  std::string file_;
  int line_;
  std::string reason_;
};

/// Largest absolute map coordinate [m]: larger values are refused (and rounding at that size
/// already exceeds any sensor's precision).
constexpr double kMaxMapCoordinate = 1e9;

/**
 * @brief Checks rings for use as a map: at least 3 distinct vertices, finite coordinates
 *        within +-kMaxMapCoordinate, positive area, each ring simple (no edge meets a
 *        non-adjacent edge, no spike), rings meeting each other at most at single points that
 *        do not cut the free space apart, holes inside the outer ring and not inside each
 *        other: the verdicts of Boost.Geometry's is_valid, in O(n log n) for valid maps
 *        without touching rings (a sweep line; a 100,000-vertex ring of any shape takes under a
 *        second), an edge grid locating the contacts otherwise.
 * @return every issue found (empty when valid). Consecutive duplicate vertices and a repeated
 *         closing vertex are not issues (they are removed by PolygonMap).
 */
std::vector<RingIssue> validateRings(const std::vector<Ring>& rings);

/**
 * @brief A validated polygon with holes. The outer ring is counter-clockwise, holes are
 *        clockwise (normalised on construction), so the free space is on the left of every edge.
 */
class PolygonMap
{
public:
  PolygonMap() = default;

  /**
   * @brief Builds a map from rings: rings[0] is the outer boundary, the rest are holes.
   * Removes consecutive duplicate vertices and a repeated closing vertex, normalises
   * orientation, then validates.
   * @throws MapError (file = @p source, line 0) naming the ring and vertex of the first issue.
   */
  static PolygonMap fromRings(std::vector<Ring> rings, const std::string& source = "<memory>");

  const std::vector<Ring>& rings() const
  {
    return rings_;
  }
  const Ring& outer() const
  {
    return rings_.front();
  }
  std::size_t holeCount() const
  {
    return rings_.empty() ? 0 : rings_.size() - 1;
  }
  /// Every edge of every ring (outer first, then holes, in ring order).
  const std::vector<Segment>& edges() const
  {
    return edges_;
  }
  const Box2& bounds() const
  {
    return bounds_;
  }
  /// Free area: outer area minus holes [m^2].
  double area() const
  {
    return area_;
  }
  bool empty() const
  {
    return rings_.empty();
  }

  /// Brute-force free-space test: inside the outer ring and outside every hole (O(edges)).
  bool containsBruteForce(const Vec2& p) const;

  /// A copy scaled about the origin by @p factor (> 0).
  PolygonMap scaled(double factor) const;

  /// Stable 64-bit hash of the geometry (for cache keys).
  std::uint64_t hash() const;

private:
  std::vector<Ring> rings_;
  std::vector<Segment> edges_;
  Box2 bounds_;
  double area_ = 0.0;
};

/**
 * @brief Removes consecutive duplicate vertices (closer than 1e-12 m) and a closing vertex
 *        equal to the first.
 * @param kept when not null, receives for each vertex of the result its index in @p ring
 */
Ring cleanRing(const Ring& ring, std::vector<std::size_t>* kept = nullptr);

}  // namespace core
}  // namespace fdml_localization
