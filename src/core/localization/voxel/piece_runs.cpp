// Runs of map edges for pieceBound() (piece_runs.h); the argument is in docs/METHOD.md.
#include "fdml_localization/core/localization/voxel/piece_runs.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace piece
{
int edgeAt(const EdgeRings& rings, int ring, int position)
{
  const int n = rings.size[ring];
  return rings.start[ring] + ((position % n) + n) % n;
}

/// Runs of the hit edges: per ring, positions split where the cyclic gap exceeds kMaxGap.
bool groupRuns(const EdgeRings& rings, Scratch& scratch)
{
  std::vector<int>& edges = scratch.edges;
  std::vector<Run>& runs = scratch.runs;
  runs.clear();
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  std::size_t i = 0;
  while (i < edges.size())
  {
    const int ring = rings.ring[edges[i]];
    const int n = rings.size[ring];
    std::vector<int>& pos = scratch.positions;
    pos.clear();
    for (; i < edges.size() && rings.ring[edges[i]] == ring; ++i)
    {
      pos.push_back(edges[i] - rings.start[ring]);
    }
    // Start after the largest cyclic gap.
    std::size_t begin = 0;
    int largest = -1;
    for (std::size_t k = 0; k < pos.size(); ++k)
    {
      const int gap = (pos[(k + 1) % pos.size()] - pos[k] + n) % n;
      if (gap > largest || pos.size() == 1)
      {
        largest = gap;
        begin = (k + 1) % pos.size();
      }
    }
    Run run{ ring, pos[begin], 1, 0, 0 };
    for (std::size_t k = 1; k < pos.size(); ++k)
    {
      const int p = pos[(begin + k) % pos.size()];
      const int gap = (p - (run.first + run.count - 1) + n) % n;
      if (gap > kMaxGap)
      {
        runs.push_back(run);
        run = Run{ ring, p, 1, 0, 0 };
      }
      else
      {
        run.count += gap;
      }
    }
    runs.push_back(run);
  }
  return runs.size() <= static_cast<std::size_t>(kMaxRuns) &&
         std::all_of(runs.begin(), runs.end(), [](const Run& r) { return r.count <= kMaxRunEdges; });
}

/// Fills run.points: the hits' extreme points on the end edges, extended over the part of the
/// end edges inside the wedge, and the inner vertices.
void runPoints(const Frame& f, Run& run)
{
  const std::vector<std::pair<int, double>>& params = f.scratch.params;
  std::vector<Vec2>& points = f.scratch.points;
  const std::vector<Segment>& segs = f.map.grid().segments();
  const int first = edgeAt(f.rings, run.ring, run.first);
  const int last = edgeAt(f.rings, run.ring, run.first + run.count - 1);
  double lo = kInf;
  double hi = -kInf;
  for (const auto& [edge, t] : params)
  {
    if (edge == first)
    {
      lo = std::min(lo, t);
    }
    if (edge == last)
    {
      hi = std::max(hi, t);
    }
  }
  auto extend = [&](int edge, double& a, double& b) {
    Vec2 p = segs[edge].a;
    Vec2 q = segs[edge].b;
    const double len2 = (q - p).squaredNorm();
    if (len2 > 0.0 && clipSegment(p, q, f.scratch.wedge))
    {
      a = std::min(a, (p - segs[edge].a).dot(segs[edge].b - segs[edge].a) / len2);
      b = std::max(b, (q - segs[edge].a).dot(segs[edge].b - segs[edge].a) / len2);
    }
  };
  double unused_hi = -kInf;
  double unused_lo = kInf;
  extend(first, lo, run.count == 1 ? hi : unused_hi);
  if (run.count > 1)
  {
    extend(last, unused_lo, hi);
    lo = std::min(lo, 1.0);
    hi = std::max(hi, 0.0);
  }
  lo = std::clamp(lo, 0.0, 1.0);
  hi = std::clamp(hi, 0.0, 1.0);
  const Segment& s0 = segs[first];
  run.begin = points.size();
  points.push_back(s0.a + (s0.b - s0.a) * lo);
  for (int k = 0; k + 1 < run.count; ++k)
  {
    points.push_back(segs[edgeAt(f.rings, run.ring, run.first + k)].b);
  }
  const Segment& s1 = segs[last];
  points.push_back(s1.a + (s1.b - s1.a) * hi);
  run.end = points.size();
}

/// Every ray of the piece that meets the run's line meets it ahead of its origin.
bool runAhead(const Frame& f, const Run& run)
{
  bool all_points = true;
  for (int j = 0; j < 2; ++j)
  {
    double front = -kInf;
    for (const Vec2& v : f.piece)
    {
      front = std::max(front, f.u[j].dot(v));
    }
    for (const Vec2& x : pointsOf(f, run))
    {
      all_points = all_points && f.u[j].dot(x) > front + kAhead;
    }
  }
  if (all_points)
  {
    return true;
  }
  // Or: every edge of the run faces every ray and has the whole piece strictly on its free side.
  const std::vector<Segment>& segs = f.map.grid().segments();
  for (int k = 0; k < run.count; ++k)
  {
    const Segment& s = segs[edgeAt(f.rings, run.ring, run.first + k)];
    const Vec2 d = s.b - s.a;
    const Vec2 left(-d.y(), d.x());
    if (!(f.u[0].dot(left) < 0.0 && f.u[1].dot(left) < 0.0))
    {
      return false;
    }
    for (const Vec2& v : f.piece)
    {
      if (!(cross(d, v - s.a) > kAhead * d.norm()))
      {
        return false;
      }
    }
  }
  return true;
}

/// The crossing of any ray of the piece with the segment [p, q] of @p edge lies ahead of its
/// origin: both points ahead of every vertex at t0 and t1, or the edge faces every ray with the
/// whole piece strictly on its free side.
static bool segmentAhead(const Frame& f, const Vec2& p, const Vec2& q, const Segment& edge)
{
  const std::vector<HalfPlane>& ahead = f.scratch.ahead;
  auto inside = [&](const Vec2& x) {
    return std::all_of(ahead.begin(), ahead.end(), [&](const HalfPlane& h) { return h.normal.dot(x) <= h.offset; });
  };
  if (inside(p) && inside(q))
  {
    return true;
  }
  const Vec2 d = edge.b - edge.a;
  const Vec2 left(-d.y(), d.x());
  if (!(f.u[0].dot(left) < 0.0 && f.u[1].dot(left) < 0.0))
  {
    return false;
  }
  return std::all_of(f.piece.begin(), f.piece.end(),
                     [&](const Vec2& v) { return cross(d, v - edge.a) > kAhead * d.norm(); });
}

/// Splits the runs into chains whose every segment passes segmentAhead(), clipping the others to
/// the region ahead of the piece. Chains replace the runs (their points in scratch.points).
void splitAhead(const Frame& f, std::vector<Run>& runs)
{
  Scratch& sc = f.scratch;
  const std::vector<Segment>& segs = f.map.grid().segments();
  sc.chain_points.clear();
  sc.chains.clear();
  Run chain;
  auto close = [&]() {
    chain.end = sc.chain_points.size();
    if (chain.end > chain.begin)
    {
      sc.chains.push_back(chain);
    }
    chain.begin = sc.chain_points.size();
  };
  for (const Run& run : runs)
  {
    close();
    const Vec2* pts = sc.points.data() + run.begin;
    const std::size_t n = run.end - run.begin;
    for (std::size_t i = 0; i + 1 < n; ++i)
    {
      Vec2 p = pts[i];
      Vec2 q = pts[i + 1];
      const Segment& edge = segs[edgeAt(f.rings, run.ring, run.first + static_cast<int>(i))];
      if (!segmentAhead(f, p, q, edge))
      {
        if (!clipSegment(p, q, sc.ahead))
        {
          close();
          continue;
        }
        if (!(p == pts[i]))
        {
          close();
        }
      }
      if (sc.chain_points.size() == chain.begin)
      {
        sc.chain_points.push_back(p);
      }
      sc.chain_points.push_back(q);
      chain.end = sc.chain_points.size();
      if (!(q == pts[i + 1]))
      {
        close();
      }
    }
  }
  close();
  sc.points.swap(sc.chain_points);
  runs.swap(sc.chains);
}

/// Some chain point lies on the right of every ray of the cell and some on the left.
bool bracketsEveryRay(const Frame& f, const std::vector<Run>& chains)
{
  bool right = false;
  bool left = false;
  for (const Run& c : chains)
  {
    for (const Vec2& z : pointsOf(f, c))
    {
      bool all_right = true;
      bool all_left = true;
      for (const Vec2& v : f.piece)
      {
        for (int j = 0; j < 2; ++j)
        {
          const double side = cross(f.u[j], z - v);
          all_right = all_right && side <= 0.0;
          all_left = all_left && side >= 0.0;
        }
      }
      right = right || all_right;
      left = left || all_left;
    }
  }
  return right && left;
}

/// Sufficient test that the lateral extents of two runs overlap for every ray of the piece:
/// some point y of one lies, across every heading, between two points of the other.
static bool overlap(const Frame& f, const Run& a, const Run& b)
{
  for (const Run* k : { &a, &b })
  {
    const Run& l = k == &a ? b : a;
    for (const Vec2& y : pointsOf(f, *k))
    {
      bool left = false;
      bool right = false;
      for (const Vec2& z : pointsOf(f, l))
      {
        const double s0 = cross(f.u[0], z - y);
        const double s1 = cross(f.u[1], z - y);
        left = left || (s0 >= 0.0 && s1 >= 0.0);
        right = right || (s0 <= 0.0 && s1 <= 0.0);
      }
      if (left && right)
      {
        return true;
      }
    }
  }
  return false;
}

bool runsConnected(const Frame& f, const std::vector<Run>& runs)
{
  if (runs.size() > static_cast<std::size_t>(kMaxChains))
  {
    return false;
  }
  bool reached[kMaxChains] = { true };
  std::size_t stack[kMaxChains] = { 0 };
  std::size_t top = 1;
  std::size_t count = 1;
  while (top > 0)
  {
    const std::size_t r = stack[--top];
    for (std::size_t s = 0; s < runs.size(); ++s)
    {
      if (!reached[s] && overlap(f, runs[r], runs[s]))
      {
        reached[s] = true;
        stack[top++] = s;
        ++count;
      }
    }
  }
  return count == runs.size();
}

}  // namespace piece
}  // namespace core
}  // namespace fdml_localization
