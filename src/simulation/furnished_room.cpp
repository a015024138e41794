/**
 * @file furnished_room.cpp
 * @brief Furnished rooms (see furnished_room.h). Every piece lies inside a disc (its
 *        circumscribed circle) and the discs keep the clearance from each other and from the
 *        wall, so no two rings can touch: the map is valid by construction.
 */
#include "fdml_localization/simulation/furnished_room.h"

#include "fdml_localization/core/geometry/geometry.h"
#include "fdml_localization/simulation/map_generators.h"

#include <cmath>
#include <random>
#include <sstream>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Placement tries per piece before the room counts as full.
constexpr int kTriesPerPiece = 200;

void validate(const FurnishedRoomOptions& o)
{
  requireOption(std::isfinite(o.width) && o.width >= 1.0 && o.width <= 1000.0, "width", o.width, "[1, 1000] m");
  requireOption(o.round || (std::isfinite(o.height) && o.height >= 1.0 && o.height <= 1000.0), "height", o.height,
                "[1, 1000] m");
  requireOption(!o.round || (o.wall_edges >= 8 && o.wall_edges <= 4096), "wall_edges", o.wall_edges,
                "an integer in [8, 4096]");
  requireOption(o.pieces >= 0 && o.pieces <= 1000, "pieces", o.pieces, "an integer in [0, 1000]");
  requireOption(std::isfinite(o.min_size) && o.min_size >= 0.01, "min_size", o.min_size, "[0.01, max_size] m");
  requireOption(std::isfinite(o.max_size) && o.max_size >= o.min_size && o.max_size <= 0.25 * o.width &&
                    (o.round || o.max_size <= 0.25 * o.height),
                "max_size", o.max_size, "[min_size, a quarter of the room's smaller side] m");
  requireOption(std::isfinite(o.clearance) && o.clearance >= 0.01 && o.clearance <= 10.0, "clearance", o.clearance,
                "[0.01, 10] m");
  requireOption(std::isfinite(o.rotation), "rotation", o.rotation, "a finite angle [rad]");
}

/// A regular polygon of @p sides around @p centre, radius @p r, first vertex at @p phase [rad].
Ring regularPolygon(const Vec2& centre, double r, int sides, double phase)
{
  Ring ring;
  for (int i = 0; i < sides; ++i)
  {
    const double a = phase + kTwoPi * i / sides;
    ring.emplace_back(centre.x() + r * std::cos(a), centre.y() + r * std::sin(a));
  }
  return ring;
}

/// A piece of furniture and its circumscribed disc.
struct Piece
{
  Ring ring;
  Vec2 centre;
  double radius = 0.0;
};

/// A random box or pillar at the origin.
Piece drawPiece(const FurnishedRoomOptions& o, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto size = [&] { return o.min_size + (o.max_size - o.min_size) * unit(rng); };
  Piece piece;
  if (unit(rng) < 0.5)
  {
    const double a = 0.5 * size();
    const double b = 0.5 * size();
    const double heading = kPi * unit(rng);
    const double c = std::cos(heading);
    const double s = std::sin(heading);
    for (const Vec2& corner : { Vec2(-a, -b), Vec2(a, -b), Vec2(a, b), Vec2(-a, b) })
    {
      piece.ring.emplace_back(c * corner.x() - s * corner.y(), s * corner.x() + c * corner.y());
    }
    piece.radius = std::hypot(a, b);
  }
  else
  {
    piece.radius = 0.5 * size();
    const int sides = 8 + static_cast<int>(17.0 * unit(rng)) % 17;  // 8 to 24
    piece.ring = regularPolygon(Vec2::Zero(), piece.radius, sides, kTwoPi * unit(rng));
  }
  return piece;
}

/// True when a disc of radius @p r around @p c lies inside the room, the clearance off its wall.
bool insideRoom(const FurnishedRoomOptions& o, const Vec2& c, double r)
{
  const double keep = r + o.clearance;
  if (o.round)
  {
    const double apothem = 0.5 * o.width * std::cos(kPi / o.wall_edges);
    return c.norm() <= apothem - keep;
  }
  return std::abs(c.x()) <= 0.5 * o.width - keep && std::abs(c.y()) <= 0.5 * o.height - keep;
}

/// The pieces placed at random where they keep the clearance.
std::vector<Piece> placePieces(const FurnishedRoomOptions& o, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Piece> placed;
  for (long tries = 0; static_cast<int>(placed.size()) < o.pieces && tries < long{ kTriesPerPiece } * o.pieces; ++tries)
  {
    Piece piece = drawPiece(o, rng);
    const Vec2 c(o.width * (unit(rng) - 0.5), (o.round ? o.width : o.height) * (unit(rng) - 0.5));
    bool fits = insideRoom(o, c, piece.radius);
    for (std::size_t j = 0; j < placed.size() && fits; ++j)
    {
      fits = (placed[j].centre - c).norm() >= placed[j].radius + piece.radius + o.clearance;
    }
    if (fits)
    {
      for (Vec2& v : piece.ring)
      {
        v += c;
      }
      piece.centre = c;
      placed.push_back(std::move(piece));
    }
  }
  return placed;
}
}  // namespace

PolygonMap furnishedRoom(const FurnishedRoomOptions& options)
{
  validate(options);
  std::mt19937_64 rng(options.seed);
  std::vector<Ring> rings;
  if (options.round)
  {
    rings.push_back(regularPolygon(Vec2::Zero(), 0.5 * options.width, options.wall_edges, 0.0));
  }
  else
  {
    const double w = 0.5 * options.width;
    const double h = 0.5 * options.height;
    rings.push_back({ Vec2(-w, -h), Vec2(w, -h), Vec2(w, h), Vec2(-w, h) });
  }
  for (Piece& piece : placePieces(options, rng))
  {
    rings.push_back(std::move(piece.ring));
  }
  const double c = std::cos(options.rotation);
  const double s = std::sin(options.rotation);
  for (Ring& ring : rings)
  {
    for (Vec2& v : ring)
    {
      v = Vec2(c * v.x() - s * v.y(), s * v.x() + c * v.y());
    }
  }
  std::ostringstream source;
  source << "furnishedRoom(" << (options.round ? "round " : "") << options.width << " x "
         << (options.round ? options.width : options.height) << " m, " << rings.size() - 1 << " pieces, rotation "
         << options.rotation << " rad, seed " << options.seed << ")";
  return PolygonMap::fromRings(std::move(rings), source.str());
}

}  // namespace core
}  // namespace fdml_localization
