/**
 * @file map_generators.cpp
 * @brief Random star-shaped polygons and procedural buildings (see map_generators.h).
 *
 * The building's free space is a union of axis-aligned rectangles (corridors, rooms shrunk
 * by half the wall thickness, door openings bridging the walls) minus pillars, computed with
 * Boost.Geometry. Free rectangles either overlap with positive area or lie at least a wall
 * thickness apart, and door openings keep a wall thickness away from every wall corner, so
 * the free space never pinches: holes never touch each other or the outer ring.
 */
#include "fdml_localization/simulation/map_generators.h"

// Boost 1.74's overlay code trips GCC 12's -Wmaybe-uninitialized (a false positive).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/multi_polygon.hpp>
#include <boost/geometry/geometries/point_xy.hpp>
#include <boost/geometry/geometries/polygon.hpp>
#pragma GCC diagnostic pop

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
void requireOption(bool ok, const std::string& name, double value, const std::string& range)
{
  if (!ok)
  {
    std::ostringstream msg;
    msg << name << " = " << value << " is out of range (allowed: " << range << ")";
    throw std::invalid_argument(msg.str());
  }
}

namespace
{
namespace bg = boost::geometry;
using BgPoint = bg::model::d2::point_xy<double>;
using BgPolygon = bg::model::polygon<BgPoint>;
using BgMulti = bg::model::multi_polygon<BgPolygon>;

/// Layout unit [m]: the building is laid out in whole units so that coordinates meant to be
/// equal are computed from the same integers and are bit-identical.
constexpr double kUnit = 1e-4;
using Units = std::int64_t;

/// An axis-aligned rectangle in layout units.
struct Rect
{
  Units x0, y0, x1, y1;
};

Units toUnits(double metres)
{
  return static_cast<Units>(std::llround(metres / kUnit));
}

BgPolygon toPolygon(const Rect& r)
{
  BgPolygon poly;
  const double x0 = r.x0 * kUnit, y0 = r.y0 * kUnit, x1 = r.x1 * kUnit, y1 = r.y1 * kUnit;
  // Boost's default polygon is clockwise and closed.
  poly.outer() = { BgPoint(x0, y0), BgPoint(x0, y1), BgPoint(x1, y1), BgPoint(x1, y0), BgPoint(x0, y0) };
  return poly;
}

/// Union of many rectangles, merged pairwise so the work stays near n log n.
BgMulti unionOf(const std::vector<Rect>& rects)
{
  std::vector<BgMulti> layer;
  layer.reserve(rects.size());
  for (const Rect& r : rects)
  {
    layer.push_back(BgMulti{ toPolygon(r) });
  }
  while (layer.size() > 1)
  {
    std::vector<BgMulti> next;
    for (std::size_t i = 0; i + 1 < layer.size(); i += 2)
    {
      BgMulti merged;
      bg::union_(layer[i], layer[i + 1], merged);
      next.push_back(std::move(merged));
    }
    if (layer.size() % 2 == 1)
    {
      next.push_back(std::move(layer.back()));
    }
    layer = std::move(next);
  }
  return layer.empty() ? BgMulti{} : layer.front();
}

/// Converts a Boost ring to ours, dropping the closing vertex and collinear vertices.
template <typename BgRing>
Ring toRing(const BgRing& in)
{
  Ring pts;
  for (const BgPoint& p : in)
  {
    pts.emplace_back(p.x(), p.y());
  }
  pts = cleanRing(pts);
  Ring out;
  const std::size_t n = pts.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Vec2& a = pts[(i + n - 1) % n];
    const Vec2& b = pts[i];
    const Vec2& c = pts[(i + 1) % n];
    const Vec2 u = b - a, v = c - b;
    const double cross = u.x() * v.y() - u.y() * v.x();
    if (std::abs(cross) > 1e-12 * (u.norm() * v.norm()) || u.dot(v) < 0.0)
    {
      out.push_back(b);
    }
  }
  return out;
}

/// Splits @p length into pieces near @p target, each at least @p min_piece, with random jitter.
std::vector<Units> splitLength(Units length, Units target, Units min_piece, std::mt19937_64& rng)
{
  Units count = std::max<Units>(1, (length + target / 2) / target);
  while (count > 1 && length / count < min_piece)
  {
    --count;
  }
  std::uniform_real_distribution<double> jitter(0.8, 1.2);
  std::vector<double> weights(count);
  double sum = 0.0;
  for (double& w : weights)
  {
    w = jitter(rng);
    sum += w;
  }
  std::vector<Units> pieces(count);
  Units used = 0;
  for (Units i = 0; i + 1 < count; ++i)
  {
    pieces[i] = static_cast<Units>(std::llround(length * weights[i] / sum));
    used += pieces[i];
  }
  pieces.back() = length - used;
  // Jitter must not push a piece below the minimum: fall back to equal pieces.
  if (*std::min_element(pieces.begin(), pieces.end()) < min_piece)
  {
    std::fill(pieces.begin(), pieces.end(), length / count);
    pieces.back() = length - (count - 1) * (length / count);
  }
  return pieces;
}

}  // namespace

PolygonMap randomPolygon(int vertices, double mean_radius, double radius_noise, std::uint64_t seed)
{
  requireOption(vertices >= 3, "vertices", vertices, "an integer >= 3");
  requireOption(std::isfinite(mean_radius) && mean_radius > 0.0, "mean_radius", mean_radius, "(0, inf) m");
  requireOption(std::isfinite(radius_noise) && radius_noise >= 0.0 && radius_noise < 1.0, "radius_noise", radius_noise,
                "[0, 1)");

  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const double min_gap = 1e-3 * kTwoPi / vertices;
  std::vector<double> angles(vertices);
  bool ok = false;
  // Sorted uniform angles; reject draws with a gap of pi or more (the polygon would not be
  // star-shaped about the origin) or with nearly coincident angles.
  for (int attempt = 0; attempt < 1000 && !ok; ++attempt)
  {
    for (double& a : angles)
    {
      a = kTwoPi * unit(rng);
    }
    std::sort(angles.begin(), angles.end());
    ok = true;
    for (int i = 0; i < vertices && ok; ++i)
    {
      const double next = (i + 1 < vertices) ? angles[i + 1] : angles[0] + kTwoPi;
      const double gap = next - angles[i];
      ok = gap > min_gap && gap < 0.9 * kPi;
    }
  }
  if (!ok)
  {
    // Stratified fallback (only reachable for tiny vertex counts): one angle per sector.
    for (int i = 0; i < vertices; ++i)
    {
      angles[i] = kTwoPi * (i + 0.1 + 0.8 * unit(rng)) / vertices;
    }
  }
  Ring ring;
  ring.reserve(vertices);
  for (double a : angles)
  {
    const double r = mean_radius * (1.0 + radius_noise * (2.0 * unit(rng) - 1.0));
    ring.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  std::ostringstream source;
  source << "randomPolygon(" << vertices << ", " << mean_radius << ", " << radius_noise << ", seed " << seed << ")";
  return PolygonMap::fromRings({ ring }, source.str());
}

namespace
{
void validateBuildingOptions(const BuildingOptions& o)
{
  requireOption(std::isfinite(o.wall_thickness) && o.wall_thickness >= 4.0 * kUnit && o.wall_thickness <= 1.0,
                "wall_thickness", o.wall_thickness, "[0.0004, 1] m");
  requireOption(std::isfinite(o.door_width) && o.door_width >= 0.1 && o.door_width <= 100.0, "door_width", o.door_width,
                "[0.1, 100] m");
  requireOption(std::isfinite(o.corridor_width) && o.corridor_width >= 2.0 * o.wall_thickness &&
                    o.corridor_width <= 100.0,
                "corridor_width", o.corridor_width, "[2 * wall_thickness, 100] m");
  // A room must hold a door a wall thickness away from each corner.
  const double min_room = std::max(o.door_width + 4.0 * o.wall_thickness, 1.0);
  requireOption(std::isfinite(o.room_size) && o.room_size >= min_room && o.room_size <= 1000.0, "room_size",
                o.room_size, "[max(door_width + 4 * wall_thickness, 1), 1000] m");
  const double min_side = 2.0 * min_room + o.corridor_width;
  requireOption(std::isfinite(o.width) && o.width >= min_side && o.width <= 10000.0, "width", o.width,
                "[2 * max(door_width + 4 * wall_thickness, 1) + corridor_width, 10000] m");
  requireOption(std::isfinite(o.height) && o.height >= min_side && o.height <= 10000.0, "height", o.height,
                "[2 * max(door_width + 4 * wall_thickness, 1) + corridor_width, 10000] m");
  requireOption(o.pillar_probability >= 0.0 && o.pillar_probability <= 1.0, "pillar_probability", o.pillar_probability,
                "[0, 1]");
}

/// The building's plan in layout units, and the random draws that fill it.
struct BuildingPlan
{
  const BuildingOptions& o;
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> unit{ 0.0, 1.0 };
  Units t = 0;           ///< wall thickness, a multiple of 4 units (half and 3/4 are whole units)
  Units h = 0;           ///< half the wall thickness
  Units door_reach = 0;  ///< how far a door opening reaches either side of its wall
  Units c = 0, d = 0, room = 0, width = 0, height = 0, min_room_u = 0;
  Units bands = 1;              ///< bands of [room row, corridor, room row] along y
  Units row_h = 0;              ///< height of a row of rooms
  std::vector<Units> block_w;   ///< widths of the blocks of rooms between vertical corridors
  std::vector<Units> block_x0;  ///< where each block starts
  std::vector<Rect> free_rects;
  std::vector<Rect> pillars;

  explicit BuildingPlan(const BuildingOptions& options) : o(options), rng(options.seed)
  {
    t = 4 * std::max<Units>(1, toUnits(o.wall_thickness / 4.0));
    h = t / 2;
    door_reach = 3 * t / 4;
    c = toUnits(o.corridor_width);
    d = toUnits(o.door_width);
    room = toUnits(o.room_size);
    width = toUnits(o.width);
    height = toUnits(o.height);
    min_room_u = std::max<Units>(d + 4 * t, toUnits(1.0));
  }

  Units randomBetween(Units lo, Units hi)
  {
    return lo + static_cast<Units>(std::floor((hi - lo) * unit(rng)));
  }
};

/// Rows of rooms along y, blocks along x separated by vertical corridors (added as free space).
void planBandsAndBlocks(BuildingPlan& p)
{
  const BuildingOptions& o = p.o;
  p.bands = std::max<Units>(1, static_cast<Units>(std::llround(o.height / (2.0 * o.room_size + o.corridor_width))));
  while (p.bands > 1 && (p.height - p.bands * p.c) / (2 * p.bands) < p.min_room_u)
  {
    --p.bands;
  }
  p.row_h = (p.height - p.bands * p.c) / (2 * p.bands);
  requireOption(p.row_h >= p.min_room_u, "height", o.height,
                "large enough for a row of rooms on each side of a corridor");
  Units vcorr =
      std::max<Units>(1, static_cast<Units>(std::llround(o.width / (3.0 * o.room_size + o.corridor_width))) - 1);
  while (vcorr > 1 && (p.width - vcorr * p.c) / (vcorr + 1) < p.min_room_u)
  {
    --vcorr;
  }
  p.block_w = splitLength(p.width - vcorr * p.c, (p.width - vcorr * p.c) / (vcorr + 1), p.min_room_u, p.rng);
  requireOption(static_cast<Units>(p.block_w.size()) == vcorr + 1 &&
                    *std::min_element(p.block_w.begin(), p.block_w.end()) >= p.min_room_u,
                "width", o.width, "large enough for a room on each side of a vertical corridor");
  Units x = 0;
  for (std::size_t b = 0; b < p.block_w.size(); ++b)
  {
    p.block_x0.push_back(x);
    x += p.block_w[b];
    if (b + 1 < p.block_w.size())
    {
      p.free_rects.push_back({ x + p.h, p.h, x + p.c - p.h, p.height - p.h });  // vertical corridor
      x += p.c;
    }
  }
}

/// One block's rooms in the row [ry0, ry1], each with a door to the corridor wall at wall_y,
/// sometimes a door to the next room, sometimes a pillar.
void addRooms(BuildingPlan& p, std::size_t block, Units ry0, Units ry1, Units wall_y)
{
  const Units pillar = std::max(toUnits(0.3), 2 * p.t);
  const Units pillar_margin = std::max(toUnits(0.5), p.t);
  const std::vector<Units> widths = splitLength(p.block_w[block], p.room, p.min_room_u, p.rng);
  Units rx0 = p.block_x0[block];
  for (std::size_t k = 0; k < widths.size(); ++k)
  {
    const Units rx1 = rx0 + widths[k];
    const Rect r{ rx0 + p.h, ry0 + p.h, rx1 - p.h, ry1 - p.h };
    p.free_rects.push_back(r);
    // Door to the corridor, a wall thickness away from the room's corners.
    const Units dx = p.randomBetween(r.x0 + p.t, r.x1 - p.t - p.d);
    p.free_rects.push_back({ dx, wall_y - p.door_reach, dx + p.d, wall_y + p.door_reach });
    if (k + 1 < widths.size() && p.unit(p.rng) < 0.35)
    {
      const Units dy = p.randomBetween(r.y0 + p.t, r.y1 - p.t - p.d);
      p.free_rects.push_back({ rx1 - p.door_reach, dy, rx1 + p.door_reach, dy + p.d });
    }
    const Units px_room = r.x1 - r.x0 - pillar - 2 * pillar_margin;
    const Units py_room = r.y1 - r.y0 - pillar - 2 * pillar_margin;
    if (p.unit(p.rng) < p.o.pillar_probability && px_room > 0 && py_room > 0)
    {
      const Units px = p.randomBetween(r.x0 + pillar_margin, r.x0 + pillar_margin + px_room);
      const Units py = p.randomBetween(r.y0 + pillar_margin, r.y0 + pillar_margin + py_room);
      p.pillars.push_back({ px, py, px + pillar, py + pillar });
    }
    rx0 = rx1;
  }
}

/// The free space (rectangles minus pillars) as one polygon with holes.
PolygonMap assemble(const BuildingPlan& p)
{
  BgMulti free_space = unionOf(p.free_rects);
  if (!p.pillars.empty())
  {
    BgMulti with_pillars;
    bg::difference(free_space, unionOf(p.pillars), with_pillars);
    free_space = std::move(with_pillars);
  }
  std::ostringstream source;
  source << "generateBuilding(" << p.o.width << " x " << p.o.height << ", seed " << p.o.seed << ")";
  if (free_space.size() != 1)
  {
    throw MapError(source.str(), 0, "free space has " + std::to_string(free_space.size()) + " components, expected 1");
  }
  std::vector<Ring> rings;
  rings.push_back(toRing(free_space.front().outer()));
  for (const auto& inner : free_space.front().inners())
  {
    rings.push_back(toRing(inner));
  }
  return PolygonMap::fromRings(std::move(rings), source.str());
}
}  // namespace

PolygonMap generateBuilding(const BuildingOptions& o)
{
  validateBuildingOptions(o);
  BuildingPlan p(o);
  planBandsAndBlocks(p);
  for (Units band = 0; band < p.bands; ++band)
  {
    const Units y0 = band * (2 * p.row_h + p.c);
    const Units yc0 = y0 + p.row_h, yc1 = yc0 + p.c;  // corridor of this band
    p.free_rects.push_back({ p.h, yc0 + p.h, p.width - p.h, yc1 - p.h });
    for (int side = 0; side < 2; ++side)
    {
      const Units ry0 = side == 0 ? y0 : yc1;
      const Units wall_y = side == 0 ? yc0 : yc1;  // the wall shared with the corridor
      for (std::size_t b = 0; b < p.block_w.size(); ++b)
      {
        addRooms(p, b, ry0, ry0 + p.row_h, wall_y);
      }
    }
  }
  return assemble(p);
}

}  // namespace core
}  // namespace fdml_localization
