#include "fdml_localization/core/map/polygon_map.h"

#include <boost/geometry.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>

#include <algorithm>
#include <cstring>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace bg = boost::geometry;

namespace
{
using BgPoint = bg::model::d2::point_xy<double>;
// Counter-clockwise outer ring, clockwise holes, open rings: the same conventions as PolygonMap.
using BgPolygon = bg::model::polygon<BgPoint, false, false>;

std::string formatMessage(const std::string& file, int line, const std::string& reason)
{
  std::ostringstream os;
  os << file;
  if (line > 0)
  {
    os << ":" << line;
  }
  os << ": " << reason;
  return os.str();
}

BgPolygon toBoost(const Ring& outer, const std::vector<const Ring*>& holes = {})
{
  BgPolygon poly;
  for (const Vec2& v : outer)
  {
    poly.outer().emplace_back(v.x(), v.y());
  }
  for (const Ring* hole : holes)
  {
    poly.inners().emplace_back();
    for (const Vec2& v : *hole)
    {
      poly.inners().back().emplace_back(v.x(), v.y());
    }
  }
  return poly;
}

Ring oriented(const Ring& ring, bool counter_clockwise)
{
  Ring out = ring;
  if ((signedArea(out) > 0.0) != counter_clockwise)
  {
    std::reverse(out.begin(), out.end());
  }
  return out;
}

/// The first edge of @p a that meets a non-adjacent edge of @p b (a == b: the same ring).
/// Returns the index of the edge's first vertex in a, or -1.
long firstCrossingEdge(const Ring& a, const Ring& b, bool same_ring)
{
  const std::size_t na = a.size();
  const std::size_t nb = b.size();
  for (std::size_t i = 0; i < na; ++i)
  {
    const Segment s{ a[i], a[(i + 1) % na] };
    for (std::size_t j = same_ring ? i + 1 : 0; j < nb; ++j)
    {
      if (same_ring && (j == i || (j + 1) % na == i || (i + 1) % na == j))
      {
        // Adjacent edges share a vertex; they are invalid only when they fold back on each other.
        if (j != i)
        {
          const Segment t{ b[j], b[(j + 1) % nb] };
          const Vec2 shared = (j == (i + 1) % na) ? a[(i + 1) % na] : a[i];
          const Vec2 u = (s.a == shared ? s.b : s.a) - shared;
          const Vec2 w = (t.a == shared ? t.b : t.a) - shared;
          if (std::abs(u.x() * w.y() - u.y() * w.x()) <= 1e-12 * u.norm() * w.norm() && u.dot(w) > 0.0)
          {
            return static_cast<long>(i);
          }
        }
        continue;
      }
      if (segmentsIntersect(s, Segment{ b[j], b[(j + 1) % nb] }))
      {
        return static_cast<long>(i);
      }
    }
  }
  return -1;
}

std::string failureText(bg::validity_failure_type failure)
{
  switch (failure)
  {
    case bg::failure_few_points:
      return "too few distinct vertices (need at least 3)";
    case bg::failure_wrong_topological_dimension:
      return "ring has no area (its vertices are collinear)";
    case bg::failure_spikes:
      return "ring folds back on itself (a spike)";
    case bg::failure_self_intersections:
      return "edges cross each other";
    case bg::failure_interior_rings_outside:
      return "hole is not inside the outer boundary";
    case bg::failure_nested_interior_rings:
      return "hole lies inside another hole";
    case bg::failure_disconnected_interior:
      return "holes split the free space into disconnected parts";
    case bg::failure_intersecting_interiors:
      return "holes overlap";
    case bg::failure_invalid_coordinate:
      return "non-finite coordinate";
    default:
      return std::string("invalid geometry (") + bg::validity_failure_type_message(failure) + ")";
  }
}
}  // namespace

MapError::MapError(const std::string& file, int line, const std::string& reason)
  : std::runtime_error(formatMessage(file, line, reason)), file_(file), line_(line), reason_(reason)
{}

Ring cleanRing(const Ring& ring, std::vector<std::size_t>* kept)
{
  Ring out;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < ring.size(); ++i)
  {
    if (!out.empty() && (ring[i] - out.back()).norm() < 1e-12)
    {
      continue;
    }
    out.push_back(ring[i]);
    index.push_back(i);
  }
  while (out.size() > 1 && (out.back() - out.front()).norm() < 1e-12)
  {
    out.pop_back();
    index.pop_back();
  }
  if (kept != nullptr)
  {
    *kept = std::move(index);
  }
  return out;
}

std::vector<RingIssue> validateRings(const std::vector<Ring>& rings)
{
  std::vector<RingIssue> issues;
  if (rings.empty())
  {
    issues.push_back({ 0, 0, "map has no rings" });
    return issues;
  }
  // 1. Each ring on its own: finite, enough vertices, an area, no self-crossing.
  std::vector<bool> ring_ok(rings.size(), false);
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    const Ring& ring = rings[r];
    const auto bad = std::find_if(ring.begin(), ring.end(), [](const Vec2& v) { return !v.allFinite(); });
    if (bad != ring.end())
    {
      issues.push_back({ r, static_cast<std::size_t>(bad - ring.begin()), "non-finite coordinate" });
      continue;
    }
    std::vector<std::size_t> kept;
    const Ring clean = cleanRing(ring, &kept);
    if (clean.size() < 3)
    {
      issues.push_back({ r, 0, "ring has " + std::to_string(clean.size()) + " distinct vertices (need at least 3)" });
      continue;
    }
    const BgPolygon poly = toBoost(oriented(clean, true));
    bg::validity_failure_type failure;
    if (!bg::is_valid(poly, failure))
    {
      const long edge = firstCrossingEdge(clean, clean, true);
      const std::size_t vertex = edge >= 0 ? kept[static_cast<std::size_t>(edge)] : 0;
      std::string reason = failureText(failure);
      if (failure == bg::failure_self_intersections || failure == bg::failure_spikes)
      {
        reason = (r == 0 ? "outer boundary" : "hole") + std::string(" crosses itself: ") + reason;
      }
      issues.push_back({ r, vertex, reason });
      continue;
    }
    ring_ok[r] = true;
  }
  if (!issues.empty())
  {
    return issues;
  }
  // 2. The rings together: holes inside the outer ring, not crossing or nesting.
  std::vector<Ring> clean;
  std::vector<std::vector<std::size_t>> kept(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    clean.push_back(oriented(cleanRing(rings[r], &kept[r]), r == 0));
    if (signedArea(cleanRing(rings[r])) * (r == 0 ? 1.0 : -1.0) < 0.0)
    {
      // The orientation flip reversed vertex order; keep the index map aligned.
      std::reverse(kept[r].begin(), kept[r].end());
    }
  }
  std::vector<const Ring*> holes;
  for (std::size_t r = 1; r < clean.size(); ++r)
  {
    holes.push_back(&clean[r]);
  }
  bg::validity_failure_type failure;
  if (bg::is_valid(toBoost(clean[0], holes), failure))
  {
    return issues;
  }
  const BgPolygon outer = toBoost(clean[0]);
  for (std::size_t r = 1; r < clean.size(); ++r)
  {
    const long edge = firstCrossingEdge(clean[r], clean[0], false);
    if (edge >= 0)
    {
      issues.push_back({ r, kept[r][static_cast<std::size_t>(edge)], "hole crosses the outer boundary" });
      continue;
    }
    if (!bg::within(toBoost(oriented(clean[r], true)), outer))
    {
      issues.push_back({ r, kept[r][0], "hole is not inside the outer boundary" });
      continue;
    }
    for (std::size_t q = 1; q < r; ++q)
    {
      const long e = firstCrossingEdge(clean[r], clean[q], false);
      if (e >= 0 || pointInRing(clean[r][0], clean[q]) || pointInRing(clean[q][0], clean[r]))
      {
        issues.push_back({ r, kept[r][e >= 0 ? static_cast<std::size_t>(e) : 0],
                           "hole overlaps the hole starting at ring " + std::to_string(q + 1) });
        break;
      }
    }
  }
  if (issues.empty())
  {
    issues.push_back({ 0, 0, failureText(failure) });
  }
  return issues;
}

PolygonMap PolygonMap::fromRings(std::vector<Ring> rings, const std::string& source)
{
  const std::vector<RingIssue> issues = validateRings(rings);
  if (!issues.empty())
  {
    const RingIssue& first = issues.front();
    throw MapError(source, 0,
                   "ring " + std::to_string(first.ring + 1) + " vertex " + std::to_string(first.vertex + 1) + ": " +
                       first.reason);
  }
  PolygonMap map;
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    map.rings_.push_back(oriented(cleanRing(rings[r]), r == 0));
  }
  for (const Ring& ring : map.rings_)
  {
    for (std::size_t i = 0; i < ring.size(); ++i)
    {
      map.edges_.push_back(Segment{ ring[i], ring[(i + 1) % ring.size()] });
      map.bounds_.extend(ring[i]);
    }
    map.area_ += signedArea(ring);  // holes are clockwise: they subtract
  }
  return map;
}

bool PolygonMap::containsBruteForce(const Vec2& p) const
{
  if (rings_.empty() || !pointInRing(p, rings_.front()))
  {
    return false;
  }
  return std::none_of(rings_.begin() + 1, rings_.end(), [&p](const Ring& hole) { return pointInRing(p, hole); });
}

PolygonMap PolygonMap::scaled(double factor) const
{
  std::vector<Ring> rings = rings_;
  for (Ring& ring : rings)
  {
    for (Vec2& v : ring)
    {
      v *= factor;
    }
  }
  return fromRings(std::move(rings), "<scaled map>");
}

std::uint64_t PolygonMap::hash() const
{
  // FNV-1a over ring sizes and the bit patterns of the coordinates.
  std::uint64_t h = 1469598103934665603ULL;
  auto mix = [&h](std::uint64_t value) {
    for (int i = 0; i < 8; ++i)
    {
      h ^= (value >> (8 * i)) & 0xffULL;
      h *= 1099511628211ULL;
    }
  };
  for (const Ring& ring : rings_)
  {
    mix(ring.size());
    for (const Vec2& v : ring)
    {
      for (int axis = 0; axis < 2; ++axis)
      {
        std::uint64_t bits;
        const double value = v[axis] == 0.0 ? 0.0 : v[axis];  // fold -0 into +0
        std::memcpy(&bits, &value, sizeof(bits));
        mix(bits);
      }
    }
  }
  return h;
}

}  // namespace core
}  // namespace fdml_localization
