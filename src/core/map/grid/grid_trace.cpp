#include "fdml_localization/core/map/grid/grid_trace.h"

#include <algorithm>
#include <cstdint>

namespace fdml_localization
{
namespace core
{
namespace
{
// Side s of a cell runs from its corner s to corner s + 1 (counter-clockwise: bottom, right,
// top, left); kDir[s] is its direction and kDir[s + 1] the inward normal (the region side).
const int kDir[4][2] = { { 1, 0 }, { 0, 1 }, { -1, 0 }, { 0, -1 } };
const int kCorner[4][2] = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };

/// Walks the boundary of one region, side by side, pushing the (offset) vertices.
class BoundaryTracer
{
public:
  BoundaryTracer(const std::vector<char>& region, int width, int height, double offset)
    : region_(region)
    , width_(width)
    , height_(height)
    , offset_(offset)
    , gap_(std::min(0.125, 1.0 - 2.0 * offset - 0.03125))
    , visited_(region.size(), 0)
  {}

  /// True when side @p s of cell (x, y) is an untraced boundary side.
  bool startsRing(int x, int y, int s) const
  {
    const int* n = kDir[(s + 1) % 4];
    return in(x, y) && !in(x - n[0], y - n[1]) && !(visited_[index(x, y)] & (1u << s));
  }

  Ring trace(int x0, int y0, int s0)
  {
    Ring ring;
    int x = x0;
    int y = y0;
    int s = s0;
    do
    {
      visited_[index(x, y)] |= static_cast<std::uint8_t>(1u << s);
      step(&x, &y, &s, &ring);
    } while (!(x == x0 && y == y0 && s == s0));
    ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
    if (ring.size() > 1 && ring.front() == ring.back())
    {
      ring.pop_back();
    }
    return ring;
  }

private:
  bool in(int x, int y) const
  {
    return x >= 0 && y >= 0 && x < width_ && y < height_ && region_[index(x, y)];
  }
  std::size_t index(int x, int y) const
  {
    return static_cast<std::size_t>(y) * static_cast<std::size_t>(width_) + static_cast<std::size_t>(x);
  }

  /// From side s of cell (x, y) to the next boundary side, pushing the corner between them.
  void step(int* x, int* y, int* s, Ring* ring) const
  {
    const Vec2 d(kDir[*s][0], kDir[*s][1]);
    const Vec2 n(kDir[(*s + 1) % 4][0], kDir[(*s + 1) % 4][1]);
    const int* c = kCorner[(*s + 1) % 4];
    const Vec2 v(*x + c[0], *y + c[1]);
    const int ax = *x + kDir[*s][0];  // the cell ahead
    const int ay = *y + kDir[*s][1];
    const int dx = ax - kDir[(*s + 1) % 4][0];  // the cell ahead on the outer side
    const int dy = ay - kDir[(*s + 1) % 4][1];
    const double o = offset_;
    if (!in(ax, ay))
    {
      // Left turn around the same cell; a saddle when the diagonal cell is region too.
      if (in(dx, dy))
      {
        ring->push_back(v - (o + gap_) * d - o * n);
        ring->push_back(v + o * d + (o + gap_) * n);
      }
      else
      {
        ring->push_back(v + o * d - o * n);
      }
      *s = (*s + 1) % 4;
    }
    else if (!in(dx, dy))
    {
      *x = ax;  // straight on along the next cell's same side
      *y = ay;
    }
    else
    {
      ring->push_back(v - o * d - o * n);  // right turn onto the diagonal cell
      *x = dx;
      *y = dy;
      *s = (*s + 3) % 4;
    }
  }

  const std::vector<char>& region_;
  int width_;
  int height_;
  double offset_;
  double gap_;                         ///< half the saddle strip's width along an axis [cells]
  std::vector<std::uint8_t> visited_;  ///< one bit per side
};
}  // namespace

std::vector<Ring> traceRegionBoundaries(const std::vector<char>& region, int width, int height, double offset)
{
  BoundaryTracer tracer(region, width, height, offset);
  std::vector<Ring> rings;
  for (int y = 0; y < height; ++y)
  {
    for (int x = 0; x < width; ++x)
    {
      for (int s = 0; s < 4; ++s)
      {
        if (tracer.startsRing(x, y, s))
        {
          rings.push_back(tracer.trace(x, y, s));
        }
      }
    }
  }
  return rings;
}

}  // namespace core
}  // namespace fdml_localization
