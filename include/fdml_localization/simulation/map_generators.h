/**
 * @file map_generators.h
 * @brief Procedural maps for tests and benchmarks: random simple polygons (the paper's
 *        "random" scene) and buildings with rooms, corridors, doors and pillars.
 */
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

#include <cstdint>
#include <string>

namespace fdml_localization
{
namespace core
{
/// The generators' option check: throws std::invalid_argument "NAME = VALUE is out of range
/// (allowed: RANGE)" unless @p ok.
void requireOption(bool ok, const std::string& name, double value, const std::string& range);

/**
 * @brief A random star-shaped simple polygon: @p vertices points at sorted random angles
 *        around the origin, at radius mean_radius * (1 + noise * u), u uniform in [-1, 1].
 * @param vertices number of vertices (>= 3)
 * @param mean_radius mean radius [m]
 * @param radius_noise relative radius noise in [0, 1)
 * @param seed random seed (same seed, same polygon)
 */
PolygonMap randomPolygon(int vertices, double mean_radius, double radius_noise, std::uint64_t seed);

/// Options of the building generator.
struct BuildingOptions
{
  double width = 60.0;              ///< outer size along x [m]
  double height = 40.0;             ///< outer size along y [m]
  double corridor_width = 2.0;      ///< [m]
  double room_size = 6.0;           ///< typical room edge [m]
  double wall_thickness = 0.2;      ///< [m]
  double door_width = 1.0;          ///< [m]
  double pillar_probability = 0.3;  ///< chance a room gets a pillar
  std::uint64_t seed = 1;
};

/// A generated building: outer wall, a corridor grid, rooms off the corridors with doors,
/// interior walls as holes, and some pillars. Always valid.
PolygonMap generateBuilding(const BuildingOptions& options);

}  // namespace core
}  // namespace fdml_localization
