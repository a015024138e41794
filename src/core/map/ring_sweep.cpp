#include "fdml_localization/core/map/ring_sweep.h"

#include <algorithm>
#include <set>

namespace fdml_localization
{
namespace core
{
namespace
{
bool before(const Vec2& p, const Vec2& q)
{
  return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y());
}

/// An edge with its end points in sweep order.
struct SweepEdge
{
  Vec2 left;
  Vec2 right;
  std::size_t ring;
  std::size_t index;  ///< from vertex index to index + 1
  std::size_t ring_size;
};

/// Below-above order of edges both crossing the sweep line (exact for edges that do not
/// cross; any answer for edges that do, which are then found before the order matters).
struct Below
{
  const std::vector<SweepEdge>* edges;
  bool operator()(std::size_t i, std::size_t j) const
  {
    const SweepEdge& s = (*edges)[i];
    const SweepEdge& t = (*edges)[j];
    if (i == j)
    {
      return false;
    }
    if (!before(t.left, s.left))  // t starts at or after s: where is t relative to s's line?
    {
      const int o = orientExact(s.left, s.right, t.left);
      const int o2 = o != 0 ? o : orientExact(s.left, s.right, t.right);
      return o2 != 0 ? o2 > 0 : i < j;
    }
    const int o = orientExact(t.left, t.right, s.left);
    const int o2 = o != 0 ? o : orientExact(t.left, t.right, s.right);
    return o2 != 0 ? o2 < 0 : i < j;
  }
};

/// True when the edges meet other than consecutive edges at their shared vertex only.
bool conflict(const SweepEdge& s, const SweepEdge& t)
{
  const bool consecutive =
      s.ring == t.ring && (t.index == (s.index + 1) % s.ring_size || s.index == (t.index + 1) % s.ring_size);
  if (consecutive)
  {
    if (orientExact(s.left, s.right, t.left) != 0 || orientExact(s.left, s.right, t.right) != 0)
    {
      return false;
    }
    // Collinear: a straight run is fine, folding back onto each other is not.
    const Vec2 shared = (s.left == t.left || s.left == t.right) ? s.left : s.right;
    const Vec2 u = (s.left == shared ? s.right : s.left) - shared;
    const Vec2 w = (t.left == shared ? t.right : t.left) - shared;
    return u.dot(w) > 0.0;
  }
  return segmentsMeetExact(Segment{ s.left, s.right }, Segment{ t.left, t.right });
}
}  // namespace

bool ringsDisjointBySweep(const std::vector<Ring>& rings, const std::vector<bool>& usable)
{
  std::vector<SweepEdge> edges;
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    const std::size_t n = rings[r].size();
    for (std::size_t i = 0; usable[r] && i < n; ++i)
    {
      const Vec2& a = rings[r][i];
      const Vec2& b = rings[r][(i + 1) % n];
      edges.push_back(before(a, b) ? SweepEdge{ a, b, r, i, n } : SweepEdge{ b, a, r, i, n });
    }
  }
  // Events: (point, 0 = insert / 1 = remove, edge); at one point removals come after inserts
  // so that edges meeting there are compared.
  struct Event
  {
    Vec2 p;
    int kind;
    std::size_t edge;
  };
  std::vector<Event> events;
  events.reserve(2 * edges.size());
  for (std::size_t e = 0; e < edges.size(); ++e)
  {
    events.push_back({ edges[e].left, 0, e });
    events.push_back({ edges[e].right, 1, e });
  }
  std::sort(events.begin(), events.end(),
            [](const Event& a, const Event& b) { return before(a.p, b.p) || (a.p == b.p && a.kind < b.kind); });
  std::set<std::size_t, Below> status(Below{ &edges });
  std::vector<std::set<std::size_t, Below>::iterator> where(edges.size(), status.end());
  for (const Event& ev : events)
  {
    if (ev.kind == 0)
    {
      const auto inserted = status.insert(ev.edge);
      if (!inserted.second)
      {
        return false;  // an order contradicted by rounding: let the exact grid decide
      }
      const auto it = inserted.first;
      where[ev.edge] = it;
      if ((it != status.begin() && conflict(edges[*std::prev(it)], edges[ev.edge])) ||
          (std::next(it) != status.end() && conflict(edges[*std::next(it)], edges[ev.edge])))
      {
        return false;
      }
      continue;
    }
    const auto it = where[ev.edge];
    if (it != status.begin() && std::next(it) != status.end() && conflict(edges[*std::prev(it)], edges[*std::next(it)]))
    {
      return false;
    }
    status.erase(it);
  }
  return true;
}

}  // namespace core
}  // namespace fdml_localization
