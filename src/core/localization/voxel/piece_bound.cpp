// The bound of h over one convex piece of positions and one heading interval (cell_bounds.h);
// the argument is written out in docs/METHOD.md, "Why the truth's voxel is never pruned".
#include "fdml_localization/core/localization/voxel/piece_runs.h"

#include <algorithm>
#include <cmath>
#include <functional>

namespace fdml_localization
{
namespace core
{
namespace
{
using piece::Frame;
using piece::pointsOf;
using piece::Run;
using piece::Scratch;

/// The hull of the piece and the runs as half-planes (false when degenerate), and the bounding
/// boxes of the piece (@p near) and of the runs (@p far).
bool hullOf(const Frame& f, const std::vector<Run>& runs, Box2& near, Box2& far)
{
  std::vector<Vec2>& points = f.scratch.hull_points;
  points.assign(f.piece.begin(), f.piece.end());
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
  convexHull(points, f.scratch.hull);
  if (f.scratch.hull.size() < 3)
  {
    return false;
  }
  hullHalfPlanes(f.scratch.hull, f.scratch.planes);
  return true;
}

/// Nearest point of a map edge not facing away from every ray, inside the convex hull of the
/// piece and the runs, from the piece's bounding box [m].
double nearestInHull(const Frame& f, const std::vector<Run>& runs)
{
  Box2 near;
  Box2 far;
  if (!hullOf(f, runs, near, far))
  {
    return 0.0;
  }
  struct Context
  {
    const Frame& f;
    const Box2& near;
    double best;
  } ctx{ f, near, kInf };
  Context* c = &ctx;
  const std::function<bool(int)> visit = [c](int i) {
    const Segment& s = c->f.map.grid().segments()[static_cast<std::size_t>(i)];
    const Vec2 d = s.b - s.a;
    const Vec2 left(-d.y(), d.x());
    if (c->f.u[0].dot(left) > 0.0 && c->f.u[1].dot(left) > 0.0)
    {
      return true;  // faces away from every ray of the cell: never a first hit
    }
    Vec2 p = s.a;
    Vec2 q = s.b;
    if (clipSegment(p, q, c->f.scratch.planes))
    {
      c->best = std::min(c->best, segmentBoxDistance(p, q, c->near));
    }
    return c->best > 0.0;
  };
  // Slices of the hull {l near + (1 - l) far} between l = j / n and (j + 1) / n.
  const double span = (near.min - far.min).cwiseAbs().maxCoeff() + (near.max - far.max).cwiseAbs().maxCoeff();
  const double width = std::max({ near.size().maxCoeff(), far.size().maxCoeff(), f.map.grid().cellSize() });
  const int n = std::clamp(static_cast<int>(std::ceil(span / width)), 1, 64);
  for (int j = 0; j < n && ctx.best > 0.0; ++j)
  {
    Box2 box;
    for (double l : { static_cast<double>(j) / n, static_cast<double>(j + 1) / n })
    {
      box.extend(near.min * l + far.min * (1.0 - l));
      box.extend(near.max * l + far.max * (1.0 - l));
    }
    f.map.grid().forEachSegmentInBox(box, visit);
  }
  return ctx.best;
}

/// The hit edges and their parameters along them (scratch.edges, scratch.params); false when a
/// ray misses or does not meet its recorded edge.
bool hitParams(const Frame& f, const std::vector<int>& hits)
{
  const std::vector<Segment>& segs = f.map.grid().segments();
  for (std::size_t i = 0; i < hits.size(); ++i)
  {
    const int e = hits[i];
    if (e < 0)
    {
      return false;
    }
    const Vec2& origin = f.piece[i / 2];
    const Vec2& dir = f.u[i % 2];
    const double d = raySegmentDistance(origin, dir, segs[e]);
    if (!std::isfinite(d))
    {
      return false;
    }
    const Vec2 x = origin + dir * d;
    const Vec2 ab = segs[e].b - segs[e].a;
    f.scratch.params.emplace_back(e, std::clamp((x - segs[e].a).dot(ab) / ab.squaredNorm(), 0.0, 1.0));
    f.scratch.edges.push_back(e);
  }
  return true;
}

/// The wedge (right of the rightmost ray at t0, left of the leftmost at t1, ahead of the piece)
/// and the strictly-ahead half-planes.
void buildWedge(const Frame& f)
{
  for (int j = 0; j < 2; ++j)
  {
    const Vec2 side = j == 0 ? Vec2(f.u[0].y(), -f.u[0].x()) : Vec2(-f.u[1].y(), f.u[1].x());
    double reach = -kInf;
    double front = -kInf;
    for (const Vec2& v : f.piece)
    {
      reach = std::max(reach, side.dot(v));
      front = std::max(front, f.u[j].dot(v));
    }
    // A hair wider than the wedge: extended runs end strictly outside every ray.
    f.scratch.wedge.push_back(HalfPlane{ side, reach + piece::kWiden });
    f.scratch.wedge.push_back(HalfPlane{ -f.u[j], -front });
    f.scratch.ahead.push_back(HalfPlane{ -f.u[j], -front - piece::kAhead });
  }
}

/// Every ray of the piece crosses a run ahead of its origin: every run lies ahead (the corner
/// rays' hits bracket every ray), or the parts of the runs that do, when some of their points
/// bracket every ray; the runs' lateral extents overlap.
bool runsCoverEveryRay(const Frame& f, std::vector<Run>& runs)
{
  bool all_ahead = true;
  for (Run& run : runs)
  {
    piece::runPoints(f, run);
    all_ahead = all_ahead && piece::runAhead(f, run);
  }
  if (all_ahead && piece::runsConnected(f, runs))
  {
    return true;
  }
  piece::splitAhead(f, runs);
  return !runs.empty() && piece::bracketsEveryRay(f, runs) && piece::runsConnected(f, runs);
}
}  // namespace

DistanceInterval pieceBound(const MapRayCaster& map, const EdgeRings& rings, const std::vector<Vec2>& piece,
                            const Vec2& u0, const Vec2& u1, const std::vector<int>& hits)
{
  static thread_local Scratch scratch;
  scratch.params.clear();
  scratch.edges.clear();
  scratch.points.clear();
  scratch.wedge.clear();
  scratch.ahead.clear();
  const Frame f{ map, rings, piece, { u0, u1 }, scratch };
  buildWedge(f);
  if (!hitParams(f, hits) || !piece::groupRuns(rings, scratch) || !runsCoverEveryRay(f, scratch.runs))
  {
    return DistanceInterval{ 0.0, kInf };
  }
  DistanceInterval out{ nearestInHull(f, scratch.runs), 0.0 };
  for (const Run& run : scratch.runs)
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
