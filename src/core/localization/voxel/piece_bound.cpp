// The bound of h over one convex piece of positions and one heading interval (cell_bounds.h);
// the argument is written out in docs/METHOD.md, "Why the truth's voxel is never pruned".
#include "fdml_localization/core/localization/voxel/cell_bounds.h"

#include "fdml_localization/core/localization/voxel/cell_geometry.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kMaxGap = 3;       ///< hit edges at most this far apart along a ring share a run
constexpr int kMaxRunEdges = 8;  ///< longer runs fall back
constexpr int kMaxRuns = 4;
constexpr int kMaxChains = 8;
constexpr double kAhead = 1e-9;  ///< [m] strictness of the "ahead" tests
constexpr double kWiden = 1e-7;  ///< [m] margin of the wedge the runs are extended over

/// A connected chain of map edges: edges first..first+count-1 of a ring (cyclic) and its points.
struct Run
{
  int ring = 0;
  int first = 0;  ///< position in the ring
  int count = 0;
  std::size_t begin = 0;  ///< its points: Scratch::points[begin, end)
  std::size_t end = 0;
};

/// Per-thread buffers (the bound runs once per cell: no allocation in the steady state).
struct Scratch
{
  std::vector<std::pair<int, double>> params;
  std::vector<int> edges;
  std::vector<int> positions;
  std::vector<Run> runs;
  std::vector<Vec2> points;
  std::vector<Vec2> hull_points;
  std::vector<Vec2> hull;
  std::vector<HalfPlane> planes;
  std::vector<HalfPlane> wedge;  ///< superset of the piece's rays beyond its own extent
  std::vector<HalfPlane> ahead;  ///< strictly ahead of every vertex of the piece at t0 and t1
  std::vector<Vec2> chain_points;
  std::vector<Run> chains;
};

struct Frame
{
  const MapRayCaster& map;
  const EdgeRings& rings;
  const std::vector<Vec2>& piece;
  Vec2 u[2];
  Scratch& scratch;
};

/// The points of a run.
struct RunPoints
{
  const Vec2* b;
  const Vec2* e;
  const Vec2* begin() const
  {
    return b;
  }
  const Vec2* end() const
  {
    return e;
  }
};

RunPoints pointsOf(const Frame& f, const Run& run)
{
  return RunPoints{ f.scratch.points.data() + run.begin, f.scratch.points.data() + run.end };
}

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
      if (!(cross2(d, v - s.a) > kAhead * d.norm()))
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
bool segmentAhead(const Frame& f, const Vec2& p, const Vec2& q, const Segment& edge)
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
                     [&](const Vec2& v) { return cross2(d, v - edge.a) > kAhead * d.norm(); });
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
          const double side = cross2(f.u[j], z - v);
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
bool overlap(const Frame& f, const Run& a, const Run& b)
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
        const double s0 = cross2(f.u[0], z - y);
        const double s1 = cross2(f.u[1], z - y);
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

/// Nearest point of a front-facing map edge inside the convex hull of the piece and the runs.
double nearestInHull(const Frame& f, const std::vector<Run>& runs)
{
  std::vector<Vec2>& points = f.scratch.hull_points;
  points.assign(f.piece.begin(), f.piece.end());
  Box2 near;
  Box2 far;
  for (const Vec2& v : f.piece)
  {
    near.extend(v);
  }
  for (const Run& r : runs)
  {
    for (const Vec2& x : pointsOf(f, r))
    {
      points.push_back(x);
      far.extend(x);
    }
  }
  std::vector<Vec2>& hull = f.scratch.hull;
  convexHull(points, hull);
  if (hull.size() < 3)
  {
    return 0.0;
  }
  std::vector<HalfPlane>& planes = f.scratch.planes;
  hullHalfPlanes(hull, planes);
  const std::vector<Segment>& segs = f.map.grid().segments();
  double best = kInf;
  struct Context
  {
    const Frame& f;
    const std::vector<Segment>& segs;
    const std::vector<HalfPlane>& planes;
    const Box2& near;
    double& best;
  } ctx{ f, segs, planes, near, best };
  const Context* c = &ctx;
  const std::function<bool(int)> visit = [c](int i) {
    const Frame& f = c->f;
    const std::vector<HalfPlane>& planes = c->planes;
    const Box2& near = c->near;
    double& best = c->best;
    const Segment& s = c->segs[static_cast<std::size_t>(i)];
    const Vec2 d = s.b - s.a;
    const Vec2 left(-d.y(), d.x());
    if (f.u[0].dot(left) > 0.0 && f.u[1].dot(left) > 0.0)
    {
      return true;  // faces away from every ray of the cell: never a first hit
    }
    Vec2 p = s.a;
    Vec2 q = s.b;
    if (clipSegment(p, q, planes))
    {
      best = std::min(best, segmentBoxDistance(p, q, near));
    }
    return best > 0.0;
  };
  // Slices of the hull {l near + (1 - l) far} between l = j / n and (j + 1) / n.
  const double span = (near.min - far.min).cwiseAbs().maxCoeff() + (near.max - far.max).cwiseAbs().maxCoeff();
  const double width = std::max({ near.size().maxCoeff(), far.size().maxCoeff(), f.map.grid().cellSize() });
  const int n = std::clamp(static_cast<int>(std::ceil(span / width)), 1, 64);
  for (int j = 0; j < n && best > 0.0; ++j)
  {
    Box2 box;
    for (double l : { static_cast<double>(j) / n, static_cast<double>(j + 1) / n })
    {
      box.extend(near.min * l + far.min * (1.0 - l));
      box.extend(near.max * l + far.max * (1.0 - l));
    }
    f.map.grid().forEachSegmentInBox(box, visit);
  }
  return best;
}
}  // namespace

DistanceInterval pieceBound(const MapRayCaster& map, const EdgeRings& rings, const std::vector<Vec2>& piece, double t0,
                            double t1, const std::vector<int>& hits)
{
  const DistanceInterval fallback{ 0.0, kInf };
  static thread_local Scratch scratch;
  Frame f{ map, rings, piece, { Vec2(std::cos(t0), std::sin(t0)), Vec2(std::cos(t1), std::sin(t1)) }, scratch };
  const std::vector<Segment>& segs = map.grid().segments();
  std::vector<std::pair<int, double>>& params = scratch.params;
  std::vector<int>& edges = scratch.edges;
  params.clear();
  edges.clear();
  scratch.points.clear();
  scratch.wedge.clear();
  scratch.ahead.clear();
  for (std::size_t i = 0; i < hits.size(); ++i)
  {
    const int e = hits[i];
    if (e < 0)
    {
      return fallback;
    }
    const Vec2& origin = piece[i / 2];
    const Vec2& dir = f.u[i % 2];
    const double d = raySegmentDistance(origin, dir, segs[e]);
    if (!std::isfinite(d))
    {
      return fallback;
    }
    const Vec2 x = origin + dir * d;
    const Vec2 ab = segs[e].b - segs[e].a;
    params.emplace_back(e, std::clamp((x - segs[e].a).dot(ab) / ab.squaredNorm(), 0.0, 1.0));
    edges.push_back(e);
  }
  // The wedge: right of the rightmost ray at t0, left of the leftmost at t1, ahead of the piece.
  for (int j = 0; j < 2; ++j)
  {
    const Vec2 side = j == 0 ? Vec2(f.u[0].y(), -f.u[0].x()) : Vec2(-f.u[1].y(), f.u[1].x());
    double reach = -kInf;
    double front = -kInf;
    for (const Vec2& v : piece)
    {
      reach = std::max(reach, side.dot(v));
      front = std::max(front, f.u[j].dot(v));
    }
    // A hair wider than the wedge: extended runs end strictly outside every ray.
    scratch.wedge.push_back(HalfPlane{ side, reach + kWiden });
    scratch.wedge.push_back(HalfPlane{ -f.u[j], -front });
    scratch.ahead.push_back(HalfPlane{ -f.u[j], -front - kAhead });
  }
  if (!groupRuns(rings, scratch))
  {
    return fallback;
  }
  std::vector<Run>& runs = scratch.runs;
  bool all_ahead = true;
  for (Run& run : runs)
  {
    runPoints(f, run);
    all_ahead = all_ahead && runAhead(f, run);
  }
  // Either every run lies ahead (the corner rays' hits bracket every ray), or the parts of the
  // runs that do, when some of their points bracket every ray.
  if (!(all_ahead && runsConnected(f, runs)))
  {
    splitAhead(f, runs);
    if (runs.empty() || !bracketsEveryRay(f, runs) || !runsConnected(f, runs))
    {
      return fallback;
    }
  }
  DistanceInterval out{ nearestInHull(f, runs), 0.0 };
  for (const Run& run : runs)
  {
    for (const Vec2& x : pointsOf(f, run))
    {
      for (const Vec2& v : piece)
      {
        out.hi = std::max(out.hi, (x - v).norm());
      }
    }
  }
  return out;
}

}  // namespace core
}  // namespace fdml_localization
