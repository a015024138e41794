#include "fdml_localization/core/localization/voxel/cell_geometry.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
std::vector<Vec2> clipPolygon(const std::vector<Vec2>& poly, const HalfPlane& h)
{
  std::vector<Vec2> out;
  const std::size_t n = poly.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Vec2& p = poly[i];
    const Vec2& q = poly[(i + 1) % n];
    const double sp = h.normal.dot(p) - h.offset;
    const double sq = h.normal.dot(q) - h.offset;
    if (sp <= 0.0)
    {
      out.push_back(p);
    }
    if ((sp < 0.0 && sq > 0.0) || (sp > 0.0 && sq < 0.0))
    {
      out.push_back(p + (q - p) * (sp / (sp - sq)));
    }
  }
  return out;
}

bool clipSegment(Vec2& a, Vec2& b, const std::vector<HalfPlane>& planes)
{
  double t0 = 0.0;
  double t1 = 1.0;
  const Vec2 d = b - a;
  for (const HalfPlane& h : planes)
  {
    const double num = h.offset - h.normal.dot(a);
    const double den = h.normal.dot(d);
    if (den == 0.0)
    {
      if (num < 0.0)
      {
        return false;
      }
      continue;
    }
    const double t = num / den;
    if (den > 0.0)
    {
      t1 = std::min(t1, t);
    }
    else
    {
      t0 = std::max(t0, t);
    }
    if (t0 > t1)
    {
      return false;
    }
  }
  const Vec2 start = a + d * t0;
  b = a + d * t1;
  a = start;
  return true;
}

void convexHull(std::vector<Vec2>& points, std::vector<Vec2>& hull)
{
  std::sort(points.begin(), points.end(),
            [](const Vec2& p, const Vec2& q) { return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y()); });
  points.erase(std::unique(points.begin(), points.end()), points.end());
  if (points.size() < 3)
  {
    hull = points;
    return;
  }
  hull.resize(2 * points.size());
  std::size_t k = 0;
  auto turn = [&](const Vec2& o, const Vec2& a, const Vec2& b) { return cross(a - o, b - o); };
  for (const Vec2& p : points)
  {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], p) <= 0.0)
    {
      --k;
    }
    hull[k++] = p;
  }
  const std::size_t lower = k + 1;
  for (auto it = points.rbegin() + 1; it != points.rend(); ++it)
  {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], *it) <= 0.0)
    {
      --k;
    }
    hull[k++] = *it;
  }
  hull.resize(k - 1);
}

void hullHalfPlanes(const std::vector<Vec2>& hull, std::vector<HalfPlane>& planes)
{
  planes.clear();
  const std::size_t n = hull.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Vec2 e = hull[(i + 1) % n] - hull[i];
    const Vec2 outward(e.y(), -e.x());  // right of a counter-clockwise edge
    planes.push_back(HalfPlane{ outward, outward.dot(hull[i]) });
  }
}

namespace
{
double pointBoxDistance(const Vec2& p, const Box2& box)
{
  const double dx = std::max({ box.min.x() - p.x(), 0.0, p.x() - box.max.x() });
  const double dy = std::max({ box.min.y() - p.y(), 0.0, p.y() - box.max.y() });
  return std::hypot(dx, dy);
}
}  // namespace

bool segmentTouchesBox(const Vec2& a, const Vec2& b, const Box2& box)
{
  // Liang-Barsky against the four sides.
  double t0 = 0.0;
  double t1 = 1.0;
  const Vec2 d = b - a;
  const double num[4] = { a.x() - box.min.x(), box.max.x() - a.x(), a.y() - box.min.y(), box.max.y() - a.y() };
  const double den[4] = { -d.x(), d.x(), -d.y(), d.y() };
  for (int k = 0; k < 4; ++k)
  {
    if (den[k] == 0.0)
    {
      if (num[k] < 0.0)
      {
        return false;
      }
      continue;
    }
    const double t = num[k] / den[k];
    if (den[k] < 0.0)
    {
      t0 = std::max(t0, t);
    }
    else
    {
      t1 = std::min(t1, t);
    }
  }
  return t0 <= t1;
}

double segmentBoxDistance(const Vec2& a, const Vec2& b, const Box2& box)
{
  if (segmentTouchesBox(a, b, box))
  {
    return 0.0;
  }
  double best = std::min(pointBoxDistance(a, box), pointBoxDistance(b, box));
  const Segment seg{ a, b };
  for (const Vec2& c : { box.min, box.max, Vec2(box.min.x(), box.max.y()), Vec2(box.max.x(), box.min.y()) })
  {
    best = std::min(best, std::sqrt(pointSegmentDistanceSquared(c, seg)));
  }
  return best;
}

}  // namespace core
}  // namespace fdml_localization
