/**
 * @file furnished_room.h
 * @brief Procedural furnished rooms for tests: a rectangular room or a round hall (its wall a
 *        many-sided polygon: a curved wall as a map draws it) holding rotated boxes and round
 *        pillars, the whole turned by any angle. Walls at every angle, short edges and many
 *        occlusion edges: the geometry the axis-aligned buildings of generateBuilding() lack.
 */
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

#include <cstdint>

namespace fdml_localization
{
namespace core
{
/// Options of furnishedRoom().
struct FurnishedRoomOptions
{
  double width = 8.0;       ///< outer size along x before the rotation [m]; a round hall's diameter
  double height = 6.0;      ///< outer size along y before the rotation [m]; unused by a round hall
  bool round = false;       ///< a round hall: the outer wall a regular polygon of wall_edges sides
  int wall_edges = 72;      ///< sides of a round hall's wall
  int pieces = 20;          ///< boxes and pillars placed (fewer when they do not fit)
  double min_size = 0.1;    ///< least box side or pillar diameter [m]
  double max_size = 0.6;    ///< largest box side or pillar diameter [m]
  double clearance = 0.25;  ///< least free gap between two pieces, and between a piece and the wall [m]
  double rotation = 0.0;    ///< the whole room turned about the origin [rad]
  std::uint64_t seed = 1;
};

/**
 * @brief A room centred on the origin: the outer wall, then @p options.pieces holes, each a
 *        box (a rectangle at a random heading) or a round pillar (a regular polygon of 8 to 24
 *        sides), half of each, at random places at least the clearance apart; placement stops
 *        after 200 tries per piece. Always valid; the same options give the same map.
 * @throws std::invalid_argument naming the option and its allowed range.
 */
PolygonMap furnishedRoom(const FurnishedRoomOptions& options);

}  // namespace core
}  // namespace fdml_localization
