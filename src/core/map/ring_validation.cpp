// validateRings in O(n log n) typical time (SegmentBuckets: each edge meets only the edges
// sharing one of its cells), with the verdicts of Boost.Geometry's is_valid (the OGC rules;
// test_ring_validation.cpp compares the two).
#include "fdml_localization/core/map/polygon_map.h"
#include "fdml_localization/core/map/ring_sweep.h"
#include "fdml_localization/core/map/segment_buckets.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <tuple>

namespace fdml_localization
{
namespace core
{
namespace
{
/// One edge of a cleaned ring: from vertex `index` to the next one.
struct Edge
{
  std::size_t ring;
  std::size_t index;
  Segment seg;
};

/// How two edges of different rings meet: not at all, at one point (allowed), or more.
enum class Contact
{
  None,
  Point,
  Cross
};

Contact contact(const Segment& s, const Segment& t, Vec2& point)
{
  if (!segmentsMeetExact(s, t))
  {
    return Contact::None;
  }
  const int o1 = orientExact(s.a, s.b, t.a);
  const int o2 = orientExact(s.a, s.b, t.b);
  const int o3 = orientExact(t.a, t.b, s.a);
  const int o4 = orientExact(t.a, t.b, s.b);
  if (o1 * o2 < 0 && o3 * o4 < 0)
  {
    return Contact::Cross;
  }
  if (o1 == 0 && o2 == 0)
  {
    // Collinear: an overlap of positive length is a crossing, a shared end point a touch.
    const bool use_x = std::abs(s.b.x() - s.a.x()) + std::abs(t.b.x() - t.a.x()) >=
                       std::abs(s.b.y() - s.a.y()) + std::abs(t.b.y() - t.a.y());
    const int axis = use_x ? 0 : 1;
    const double lo = std::max(std::min(s.a[axis], s.b[axis]), std::min(t.a[axis], t.b[axis]));
    const double hi = std::min(std::max(s.a[axis], s.b[axis]), std::max(t.a[axis], t.b[axis]));
    if (hi > lo)
    {
      return Contact::Cross;
    }
  }
  const std::pair<bool, Vec2> ends[] = { { o1 == 0 && inBox(s.a, s.b, t.a), t.a },
                                         { o2 == 0 && inBox(s.a, s.b, t.b), t.b },
                                         { o3 == 0 && inBox(t.a, t.b, s.a), s.a },
                                         { o4 == 0 && inBox(t.a, t.b, s.b), s.b } };
  for (const auto& end : ends)
  {
    if (end.first)
    {
      point = end.second;
      return Contact::Point;
    }
  }
  return Contact::Cross;  // inconsistent rounding: count it against the map
}

/// True when adjacent edges (sharing vertex @p shared) fold back onto each other.
bool isSpike(const Vec2& before, const Vec2& shared, const Vec2& after)
{
  const Vec2 u = before - shared;
  const Vec2 w = after - shared;
  return std::abs(u.x() * w.y() - u.y() * w.x()) <= 1e-12 * u.norm() * w.norm() && u.dot(w) > 0.0;
}

/// Everything one pass over the edge pairs learns.
struct Contacts
{
  std::vector<long> bad_edge;    ///< per ring: first edge meeting another edge of its ring, -1 = none
  std::vector<bool> bad_spike;   ///< per ring: that problem is a spike
  std::vector<long> outer_edge;  ///< per hole: first edge crossing the outer ring, -1 = none
  std::map<std::pair<std::size_t, std::size_t>, std::size_t> hole_cross;  ///< (hole, earlier hole) -> edge
  std::vector<std::tuple<std::size_t, double, double>> touches;           ///< (ring, point), sorted, unique
};

/// The cleaned ring's own problem, or an empty reason.
std::string ringShapeProblem(const Ring& ring)
{
  if (ring.size() < 3)
  {
    return "ring has " + std::to_string(ring.size()) + " distinct vertices (need at least 3)";
  }
  for (std::size_t k = 2; k < ring.size(); ++k)
  {
    if (orientExact(ring[0], ring[1], ring[k]) != 0)
    {
      return "";
    }
  }
  return "ring has no area (its vertices are collinear)";
}

void checkSameRing(const std::vector<Ring>& rings, const Edge& a, const Edge& b, Contacts& c)
{
  const std::size_t n = rings[a.ring].size();
  const bool next = b.index == (a.index + 1) % n;
  const bool previous = a.index == (b.index + 1) % n;
  bool problem = false;
  bool spike = false;
  if (next || previous)
  {
    const Ring& ring = rings[a.ring];
    const std::size_t first = next ? a.index : b.index;
    spike = isSpike(ring[first], ring[(first + 1) % n], ring[(first + 2) % n]);
    problem = spike;
  }
  else
  {
    problem = segmentsMeetExact(a.seg, b.seg);
  }
  if (problem)
  {
    c.bad_edge[a.ring] = static_cast<long>(a.index);
    c.bad_spike[a.ring] = spike;
  }
}

void checkOtherRing(const Edge& a, const Edge& b, Contacts& c)
{
  Vec2 point;
  const Contact kind = contact(a.seg, b.seg, point);
  if (kind == Contact::Point)
  {
    c.touches.emplace_back(a.ring, point.x(), point.y());
    c.touches.emplace_back(b.ring, point.x(), point.y());
  }
  else if (kind == Contact::Cross && a.ring == 0)
  {
    long& edge = c.outer_edge[b.ring];
    edge = edge < 0 ? static_cast<long>(b.index) : std::min(edge, static_cast<long>(b.index));
  }
  else if (kind == Contact::Cross)
  {
    const auto key = std::make_pair(b.ring, a.ring);
    const auto it = c.hole_cross.find(key);
    c.hole_cross[key] = it == c.hole_cross.end() ? b.index : std::min(it->second, b.index);
  }
}

Contacts noContacts(std::size_t ring_count)
{
  Contacts c;
  c.bad_edge.assign(ring_count, -1);
  c.bad_spike.assign(ring_count, false);
  c.outer_edge.assign(ring_count, -1);
  return c;
}

/// One pass over every pair of edges sharing a grid cell (edges of rings listed in @p usable).
Contacts findContacts(const std::vector<Ring>& rings, const std::vector<bool>& usable)
{
  std::vector<Edge> edges;
  std::vector<Segment> segments;
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    for (std::size_t i = 0; usable[r] && i < rings[r].size(); ++i)
    {
      segments.push_back(Segment{ rings[r][i], rings[r][(i + 1) % rings[r].size()] });
      edges.push_back({ r, i, segments.back() });
    }
  }
  Contacts c = noContacts(rings.size());
  SegmentBuckets grid(segments);
  bool any_bad = false;
  for (std::size_t i = 0; i < edges.size(); ++i)
  {
    if (c.bad_edge[edges[i].ring] >= 0)
    {
      continue;
    }
    grid.forEachLaterNeighbour(i, [&](std::size_t j) {
      if (edges[j].ring == edges[i].ring && c.bad_edge[edges[i].ring] < 0)
      {
        checkSameRing(rings, edges[i], edges[j], c);
        any_bad = any_bad || c.bad_edge[edges[i].ring] >= 0;
      }
      else if (edges[j].ring != edges[i].ring && !any_bad)
      {
        checkOtherRing(edges[i], edges[j], c);
      }
    });
  }
  std::sort(c.touches.begin(), c.touches.end());
  c.touches.erase(std::unique(c.touches.begin(), c.touches.end()), c.touches.end());
  return c;
}

/// A point of ring @p r off every other ring's boundary (a vertex touching nothing).
Vec2 probePoint(const Ring& ring, std::size_t r, const Contacts& c)
{
  for (const Vec2& v : ring)
  {
    if (!std::binary_search(c.touches.begin(), c.touches.end(), std::make_tuple(r, v.x(), v.y())))
    {
      return v;
    }
  }
  return 0.5 * (ring[0] + ring[1]);
}

bool insideRing(const Vec2& p, const Ring& ring, const Box2& box)
{
  return p.x() >= box.min.x() && p.x() <= box.max.x() && p.y() >= box.min.y() && p.y() <= box.max.y() &&
         pointInRing(p, ring);
}

/// The first ring whose single-point contacts close a cycle (rings and touch points as a
/// graph): its free space is cut in two. -1 when there is none.
long touchCycle(const Contacts& c, std::size_t ring_count)
{
  std::map<std::pair<double, double>, std::size_t> point_node;
  std::vector<std::size_t> parent(ring_count);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&parent](std::size_t x) {
    while (parent[x] != x)
    {
      x = parent[x] = parent[parent[x]];
    }
    return x;
  };
  for (const auto& [ring, x, y] : c.touches)
  {
    const auto inserted = point_node.emplace(std::make_pair(x, y), parent.size());
    if (inserted.second)
    {
      parent.push_back(parent.size());
    }
    const std::size_t a = find(ring);
    const std::size_t b = find(inserted.first->second);
    if (a == b)
    {
      return static_cast<long>(ring);
    }
    parent[a] = b;
  }
  return -1;
}

/// Holes against the outer ring and each other, once every ring is valid on its own.
void checkHoles(const std::vector<Ring>& rings, const std::vector<std::vector<std::size_t>>& kept, const Contacts& c,
                std::vector<RingIssue>& issues)
{
  std::vector<Box2> boxes(rings.size());
  std::vector<Vec2> probes(rings.size());
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    for (const Vec2& v : rings[r])
    {
      boxes[r].extend(v);
    }
    probes[r] = probePoint(rings[r], r, c);
  }
  for (std::size_t r = 1; r < rings.size(); ++r)
  {
    if (c.outer_edge[r] >= 0)
    {
      issues.push_back({ r, kept[r][static_cast<std::size_t>(c.outer_edge[r])], "hole crosses the outer boundary" });
      continue;
    }
    if (!insideRing(probes[r], rings[0], boxes[0]))
    {
      issues.push_back({ r, kept[r][0], "hole is not inside the outer boundary" });
      continue;
    }
    for (std::size_t q = 1; q < r; ++q)
    {
      const auto cross = c.hole_cross.find({ r, q });
      if (cross != c.hole_cross.end() || insideRing(probes[r], rings[q], boxes[q]) ||
          insideRing(probes[q], rings[r], boxes[r]))
      {
        issues.push_back({ r, kept[r][cross != c.hole_cross.end() ? cross->second : 0],
                           "hole overlaps the hole starting at ring " + std::to_string(q + 1) });
        break;
      }
    }
  }
  const long cycle = issues.empty() ? touchCycle(c, rings.size()) : -1;
  if (cycle >= 0)
  {
    issues.push_back({ static_cast<std::size_t>(cycle), 0, "holes split the free space into disconnected parts" });
  }
}

/// The first non-finite or out-of-range coordinate of @p ring, or an empty reason.
std::string coordinateProblem(const Ring& ring, std::size_t& vertex)
{
  for (vertex = 0; vertex < ring.size(); ++vertex)
  {
    if (!ring[vertex].allFinite())
    {
      return "non-finite coordinate";
    }
    if (ring[vertex].cwiseAbs().maxCoeff() > kMaxMapCoordinate)
    {
      return "coordinate beyond +-1e9 m (the largest a map may use)";
    }
  }
  return "";
}
}  // namespace

std::vector<RingIssue> validateRings(const std::vector<Ring>& rings)
{
  if (rings.empty())
  {
    return { { 0, 0, "map has no rings" } };
  }
  std::vector<RingIssue> issues;
  std::vector<Ring> clean(rings.size());
  std::vector<std::vector<std::size_t>> kept(rings.size());
  std::vector<bool> usable(rings.size(), false);
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    std::size_t vertex = 0;
    std::string reason = coordinateProblem(rings[r], vertex);
    if (reason.empty())
    {
      clean[r] = cleanRing(rings[r], &kept[r]);
      reason = ringShapeProblem(clean[r]);
      vertex = 0;
    }
    usable[r] = reason.empty();
    if (!usable[r])
    {
      issues.push_back({ r, vertex, reason });
    }
  }
  // The sweep certifies the common case (no contacts at all) whatever the shape; the grid
  // then finds which edges meet, and where rings touch.
  const Contacts contacts =
      ringsDisjointBySweep(clean, usable) ? noContacts(rings.size()) : findContacts(clean, usable);
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    if (contacts.bad_edge[r] >= 0)
    {
      const std::string what = contacts.bad_spike[r] ? "ring folds back on itself (a spike)" : "edges cross each other";
      issues.push_back({ r, kept[r][static_cast<std::size_t>(contacts.bad_edge[r])],
                         (r == 0 ? "outer boundary" : "hole") + std::string(" crosses itself: ") + what });
    }
  }
  if (issues.empty())
  {
    checkHoles(clean, kept, contacts, issues);
  }
  std::stable_sort(issues.begin(), issues.end(),
                   [](const RingIssue& a, const RingIssue& b) { return a.ring < b.ring; });
  return issues;
}

}  // namespace core
}  // namespace fdml_localization
