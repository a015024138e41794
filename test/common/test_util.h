// Helpers shared by the core tests: the bundled map files and an independent (exact-predicate,
// O(n^2)) check that rings are simple and keep apart from each other.
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace test
{
/// Every .poly file under maps/ (recursively), sorted.
inline std::vector<std::string> bundledMaps()
{
  std::vector<std::string> paths;
  const std::filesystem::path root = std::filesystem::path(FDML_SOURCE_DIR) / "maps";
  for (const auto& entry : std::filesystem::recursive_directory_iterator(root))
  {
    if (entry.is_regular_file() && entry.path().extension() == ".poly")
    {
      paths.push_back(entry.path().string());
    }
  }
  std::sort(paths.begin(), paths.end());
  return paths;
}

/// The unit vector at @p angle [rad].
inline Vec2 unitDir(double angle)
{
  return Vec2(std::cos(angle), std::sin(angle));
}

/// The file name without directory, for test messages.
inline std::string baseName(const std::string& path)
{
  return std::filesystem::path(path).filename().string();
}

/// Sign of the cross product (b - a) x (c - a), written independently of the library.
inline int orient(const Vec2& a, const Vec2& b, const Vec2& c)
{
  const double v = (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
  return (v > 0.0) - (v < 0.0);
}

/// True when the closed segments pq and rs share a point.
inline bool closedSegmentsMeet(const Vec2& p, const Vec2& q, const Vec2& r, const Vec2& s)
{
  auto within = [](const Vec2& a, const Vec2& b, const Vec2& c) {
    return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
           c.y() <= std::max(a.y(), b.y());
  };
  const int o1 = orient(p, q, r), o2 = orient(p, q, s), o3 = orient(r, s, p), o4 = orient(r, s, q);
  if (o1 != o2 && o3 != o4)
  {
    return true;
  }
  return (o1 == 0 && within(p, q, r)) || (o2 == 0 && within(p, q, s)) || (o3 == 0 && within(r, s, p)) ||
         (o4 == 0 && within(r, s, q));
}

/// Distance from p to segment ab [m].
inline double distanceToSegment(const Vec2& p, const Vec2& a, const Vec2& b)
{
  const Vec2 e = b - a;
  const double len2 = e.squaredNorm();
  const double t = len2 > 0.0 ? std::clamp((p - a).dot(e) / len2, 0.0, 1.0) : 0.0;
  return (a + t * e - p).norm();
}

/// One edge of a ring, for strictRingProblem().
struct RingEdge
{
  std::size_t ring, index, count;
  Vec2 a, b;
};

/// The problem of one pair of edges (they meet, or their rings are too close); empty if none.
inline std::string ringEdgePairProblem(const RingEdge& e, const RingEdge& f, double min_gap)
{
  if (e.ring == f.ring)
  {
    const std::size_t step = (f.index + e.count - e.index) % e.count;
    if (step == 1 || step == e.count - 1)
    {
      return "";  // consecutive edges share their common vertex
    }
  }
  if (closedSegmentsMeet(e.a, e.b, f.a, f.b))
  {
    return "ring " + std::to_string(e.ring) + " edge " + std::to_string(e.index) + " meets ring " +
           std::to_string(f.ring) + " edge " + std::to_string(f.index);
  }
  if (e.ring != f.ring)
  {
    const double gap = std::min({ distanceToSegment(e.a, f.a, f.b), distanceToSegment(e.b, f.a, f.b),
                                  distanceToSegment(f.a, e.a, e.b), distanceToSegment(f.b, e.a, e.b) });
    if (gap < min_gap)
    {
      return "rings " + std::to_string(e.ring) + " and " + std::to_string(f.ring) + " are only " + std::to_string(gap) +
             " m apart";
    }
  }
  return "";
}

/// Every hole inside the outer ring and outside the other holes; empty if so.
inline std::string holeNestingProblem(const std::vector<Ring>& rings)
{
  for (std::size_t r = 1; r < rings.size(); ++r)
  {
    if (!pointInRing(rings[r][0], rings[0]))
    {
      return "hole " + std::to_string(r) + " is outside the outer ring";
    }
    for (std::size_t q = 1; q < rings.size(); ++q)
    {
      if (q != r && pointInRing(rings[r][0], rings[q]))
      {
        return "hole " + std::to_string(r) + " is inside hole " + std::to_string(q);
      }
    }
  }
  return "";
}

/**
 * @brief Empty when the rings form a valid map in the strict sense used by this project:
 *        every ring simple (only consecutive edges share their common vertex), no two rings
 *        sharing a point, rings at least @p min_gap apart, every hole inside the outer ring.
 *        Otherwise a description of the first problem.
 */
inline std::string strictRingProblem(const std::vector<Ring>& rings, double min_gap)
{
  std::vector<RingEdge> edges;
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    const std::size_t n = rings[r].size();
    if (n < 3)
    {
      return "ring " + std::to_string(r) + " has fewer than 3 vertices";
    }
    for (std::size_t k = 0; k < n; ++k)
    {
      edges.push_back({ r, k, n, rings[r][k], rings[r][(k + 1) % n] });
    }
  }
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    for (std::size_t j = i + 1; j < edges.size(); ++j)
    {
      const std::string problem = ringEdgePairProblem(edges[i], edges[j], min_gap);
      if (!problem.empty())
      {
        return problem;
      }
    }
  }
  return holeNestingProblem(rings);
}

}  // namespace test
}  // namespace core
}  // namespace fdml_localization
