/**
 * @file grid_raster.h
 * @brief Polygon map -> occupancy grid (rasterising like a SLAM map), for tests, the shipped
 *        example grids and fdml_map_rasterize.
 */
#pragma once

#include "fdml_localization/core/map/grid/occupancy_grid.h"
#include "fdml_localization/core/map/polygon_map.h"

#include <cstdint>

namespace fdml_localization
{
namespace core
{
/// Options of rasterize().
struct RasterizeOptions
{
  double resolution = 0.05;      ///< cell edge [m], > 0
  double margin = 0.5;           ///< unknown border around the map's bounds [m], >= 0
  double wall_thickness = 0.15;  ///< non-free cells this close to free space are occupied [m]
  double boundary_noise = 0.0;   ///< probability a free cell touching a wall turns occupied, [0, 1]
  int specks = 0;                ///< small random occupied blobs (1 to 2 cells a side) in free space
  int islands = 0;               ///< small free blobs in the unknown area outside the walls
  std::uint64_t seed = 1;        ///< random seed (same seed, same grid)
  /// Occupy every non-free cell inside the outer boundary (a floor plan: obstacles solid)
  /// instead of only the cells within wall_thickness of free space (a SLAM map).
  bool fill_obstacles = false;
};

/**
 * @brief Rasterises a polygon map like a SLAM map: free cells (centre inside the free space)
 *        0, cells within wall_thickness of free space 100 (with fill_obstacles, also every
 *        other cell inside the outer boundary), everything else -1, then the requested noise,
 *        specks and islands. Grid axes are the map's axes (yaw 0).
 * @throws std::invalid_argument naming the option out of range, or for an empty map.
 */
OccupancyGrid rasterize(const PolygonMap& map, const RasterizeOptions& options);

}  // namespace core
}  // namespace fdml_localization
