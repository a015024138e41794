#include "fdml_localization/core/localization/voxel/cell_bounds.h"

#include "fdml_localization/core/localization/voxel/cell_geometry.h"

#include <omp.h>

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
/// [m] positions closer than this to a wall are left out of the pieces (the rays of points on
/// a wall are not well defined).
constexpr double kWallMargin = 1e-6;
/// A position box that is not one of the simple cases is split in four, at most this many times.
constexpr int kSplitDepth = 3;

/// The free side of @p s (its left), moved in by @p margin.
HalfPlane freeSide(const Segment& s, double margin)
{
  const Vec2 d = s.b - s.a;
  const Vec2 left(-d.y(), d.x());
  return HalfPlane{ -left, -left.dot(s.a) - margin * d.norm() };
}

void addPiece(std::vector<Vec2> poly, std::vector<std::vector<Vec2>>& pieces)
{
  if (poly.size() >= 3)
  {
    pieces.push_back(std::move(poly));
  }
}

/// Hit segment of every sample ray (-1 where the sample's position is not free).
std::vector<int> sampleHits(const MapRayCaster& map, const GridSpec& spec, const std::vector<Vec2>& dirs, int threads)
{
  std::vector<int> hits(spec.voxelCount(), -1);
  const std::size_t slice = static_cast<std::size_t>(spec.nx) * spec.ny;
#pragma omp parallel for schedule(dynamic, 16) num_threads(threads)
  for (long c = 0; c < static_cast<long>(slice); ++c)
  {
    const Vec2 origin(spec.centreX(static_cast<int>(c % spec.nx)), spec.centreY(static_cast<int>(c / spec.nx)));
    if (!map.isFree(origin))
    {
      continue;
    }
    for (int it = 0; it < spec.nt; ++it)
    {
      hits[static_cast<std::size_t>(it) * slice + static_cast<std::size_t>(c)] = map.cast(origin, dirs[it]).segment;
    }
  }
  return hits;
}
}  // namespace

EdgeRings::EdgeRings(const PolygonMap& map)
{
  int first = 0;
  for (const Ring& r : map.rings())
  {
    start.push_back(first);
    size.push_back(static_cast<int>(r.size()));
    ring.insert(ring.end(), r.size(), static_cast<int>(start.size()) - 1);
    first += static_cast<int>(r.size());
  }
}

namespace
{
/// freePieces() for the simple cases only: appends, false when the box is not simple.
bool simplePieces(const MapRayCaster& map, const Box2& box, double margin, std::vector<std::vector<Vec2>>& pieces)
{
  const std::vector<Segment>& segs = map.grid().segments();
  std::vector<int> touching;
  map.grid().forEachSegmentInBox(box, [&](int i) {
    if (segmentTouchesBox(segs[i].a, segs[i].b, box))
    {
      touching.push_back(i);
    }
    return touching.size() <= 2;
  });
  const std::vector<Vec2> square = { box.min, Vec2(box.max.x(), box.min.y()), box.max, Vec2(box.min.x(), box.max.y()) };
  if (touching.empty())
  {
    if (map.isFree(0.5 * (box.min + box.max)))
    {
      pieces.push_back(square);
    }
    return true;
  }
  if (touching.size() == 1)
  {
    addPiece(clipPolygon(square, freeSide(segs[touching[0]], margin)), pieces);
    return true;
  }
  if (touching.size() > 2)
  {
    return false;
  }
  const Segment* e1 = &segs[touching[0]];
  const Segment* e2 = &segs[touching[1]];
  if (e2->b == e1->a)
  {
    std::swap(e1, e2);
  }
  if (!(e1->b == e2->a))
  {
    return false;  // two walls that do not meet inside the box
  }
  const HalfPlane h1 = freeSide(*e1, margin);
  const HalfPlane h2 = freeSide(*e2, margin);
  if (cross(e1->b - e1->a, e2->b - e2->a) >= 0.0)
  {
    addPiece(clipPolygon(clipPolygon(square, h1), h2), pieces);  // convex corner of free space
  }
  else
  {
    addPiece(clipPolygon(square, h1), pieces);  // reflex corner: free space is the union
    addPiece(clipPolygon(square, h2), pieces);
  }
  return true;
}

bool splitPieces(const MapRayCaster& map, const Box2& box, double margin, int depth,
                 std::vector<std::vector<Vec2>>& pieces)
{
  if (simplePieces(map, box, margin, pieces))
  {
    return true;
  }
  if (depth == 0)
  {
    return false;
  }
  const Vec2 mid = 0.5 * (box.min + box.max);
  for (int q = 0; q < 4; ++q)
  {
    Box2 sub;
    sub.extend(mid);
    sub.extend(Vec2(q % 2 == 0 ? box.min.x() : box.max.x(), q / 2 == 0 ? box.min.y() : box.max.y()));
    if (!splitPieces(map, sub, margin, depth - 1, pieces))
    {
      return false;
    }
  }
  return true;
}
}  // namespace

bool freePieces(const MapRayCaster& map, const Box2& box, double margin, std::vector<std::vector<Vec2>>& pieces)
{
  pieces.clear();
  return splitPieces(map, box, margin, kSplitDepth, pieces);
}

namespace
{
/// The free pieces of a position box and, per piece vertex, the segment hit at every sample
/// heading (from the table's samples when the piece is the whole box, else cast).
struct Column
{
  bool simple = false;
  std::vector<std::vector<Vec2>> pieces;
  std::vector<std::vector<int>> vertex_hits;
};

void columnPieces(const MapRayCaster& map, const GridSpec& spec, const std::vector<Vec2>& dirs,
                  const std::vector<int>& hits, int jx, int jy, Column& column)
{
  Box2 box;
  box.extend(Vec2(spec.centreX(jx), spec.centreY(jy)));
  box.extend(Vec2(spec.centreX(jx + 1), spec.centreY(jy + 1)));
  column.simple = freePieces(map, box, kWallMargin, column.pieces);
  const std::vector<std::vector<Vec2>>& pieces = column.pieces;
  const bool whole = column.simple && pieces.size() == 1 && pieces[0].size() == 4 && pieces[0][0] == box.min &&
                     pieces[0][2] == box.max;
  const int corner_x[4] = { jx, jx + 1, jx + 1, jx };
  const int corner_y[4] = { jy, jy, jy + 1, jy + 1 };
  column.vertex_hits.clear();
  for (const std::vector<Vec2>& piece : pieces)
  {
    for (std::size_t k = 0; k < piece.size(); ++k)
    {
      std::vector<int> h(spec.nt);
      for (int it = 0; it < spec.nt; ++it)
      {
        h[it] = whole ? hits[spec.index(corner_x[k], corner_y[k], it)] : map.cast(piece[k], dirs[it]).segment;
      }
      column.vertex_hits.push_back(std::move(h));
    }
  }
}

/// The union of the pieces' bounds over heading cell @p jt.
DistanceInterval cellBound(const MapRayCaster& map, const EdgeRings& rings, const GridSpec& spec,
                           const std::vector<Vec2>& dirs, const Column& column, int jt, std::vector<int>& h)
{
  if (!column.simple)
  {
    return DistanceInterval{ 0.0, kInf };
  }
  const int jt1 = (jt + 1) % spec.nt;
  DistanceInterval bound;
  std::size_t vertex = 0;
  for (const std::vector<Vec2>& piece : column.pieces)
  {
    h.clear();
    for (std::size_t k = 0; k < piece.size(); ++k, ++vertex)
    {
      h.push_back(column.vertex_hits[vertex][jt]);
      h.push_back(column.vertex_hits[vertex][jt1]);
    }
    const DistanceInterval b = pieceBound(map, rings, piece, dirs[jt], dirs[jt1], h);
    bound.lo = std::min(bound.lo, b.lo);
    bound.hi = std::max(bound.hi, b.hi);
  }
  return bound;
}
}  // namespace

CellBounds CellBounds::compute(const MapRayCaster& map, const GridSpec& spec, int threads)
{
  CellBounds out;
  out.spec_ = spec;
  const std::size_t cells = static_cast<std::size_t>(out.paddedNx()) * out.paddedNy() * spec.nt;
  out.lower_.assign(cells, std::numeric_limits<float>::infinity());
  out.upper_.assign(cells, -std::numeric_limits<float>::infinity());
  std::vector<Vec2> dirs(spec.nt);
  for (int it = 0; it < spec.nt; ++it)
  {
    dirs[it] = Vec2(std::cos(spec.centreTheta(it)), std::sin(spec.centreTheta(it)));
  }
  const std::vector<int> hits = sampleHits(map, spec, dirs, threads);
  const EdgeRings rings(map.map());
  const long columns = static_cast<long>(spec.nx - 1) * (spec.ny - 1);
  std::size_t fallback = 0;
#pragma omp parallel for schedule(dynamic, 4) num_threads(threads) reduction(+ : fallback)
  for (long c = 0; c < columns; ++c)
  {
    const int jx = static_cast<int>(c % (spec.nx - 1));
    const int jy = static_cast<int>(c / (spec.nx - 1));
    Column column;
    columnPieces(map, spec, dirs, hits, jx, jy, column);
    std::vector<int> h;
    for (int jt = 0; jt < spec.nt; ++jt)
    {
      const DistanceInterval bound = cellBound(map, rings, spec, dirs, column, jt, h);
      fallback += std::isinf(bound.hi) && bound.hi > 0.0 ? 1 : 0;
      const std::size_t i = out.index(jx, jy, jt);
      out.lower_[i] = roundDown(bound.lo);
      out.upper_[i] = roundUp(bound.hi);
    }
  }
  out.fallback_cells_ = fallback;
  return out;
}

}  // namespace core
}  // namespace fdml_localization
