/**
 * @file grid_to_polygon.h
 * @brief Occupancy grid -> polygon with holes (the map the localizer needs), and back
 *        (rasterising a polygon map into a grid, for tests and the shipped example maps).
 */
#pragma once

#include "fdml_localization/core/occupancy_grid.h"
#include "fdml_localization/core/polygon_map.h"

#include <cstdint>
#include <string>

namespace fdml_localization
{
namespace core
{
/// Options of gridToPolygon().
struct GridConversionOptions
{
  /// Douglas-Peucker tolerance [m]; <= 0 picks one cell (the grid's resolution).
  double tolerance = 0.0;
  /// Obstacles (holes) of smaller area are dropped as noise [m^2]; < 0 picks 10 cells' area.
  double min_area = -1.0;
  /// Keep the free region holding seed_point; otherwise the largest free region.
  bool use_seed = false;
  Vec2 seed_point = Vec2::Zero();  ///< map frame [m]
  /// A cell is free when 0 <= value < occupied_threshold; unknown (-1 or any value outside
  /// 0..100) and values >= occupied_threshold are walls. In [1, 100].
  int occupied_threshold = 50;
};

/// What the conversion did (for logs and the tool's summary).
struct GridConversionReport
{
  long region_cells = 0;        ///< free cells of the chosen region
  long free_cells = 0;          ///< free cells in the whole grid
  int regions = 0;              ///< free regions (4-connected) in the grid
  int holes_found = 0;          ///< obstacles inside the region before dropping specks
  int holes_dropped = 0;        ///< obstacles under min_area
  long vertices_traced = 0;     ///< vertices before simplification
  long vertices_kept = 0;       ///< vertices after simplification
  int rings_tightened = 0;      ///< rings simplified with a smaller tolerance to stay valid
  double tolerance_used = 0.0;  ///< [m]
  double min_area_used = 0.0;   ///< [m^2]
};

/**
 * @brief Converts an occupancy grid into a valid polygon with holes.
 *
 * Picks the 4-connected free region holding the seed (or the largest), traces its boundary
 * along the cell edges (so before simplification a ray meets the polygon where it meets the
 * first non-free cell; where two wall cells touch only at a corner the wall stays closed,
 * with a 1/8-cell chamfer off the free cells' corners there), drops holes under min_area,
 * simplifies every ring with Douglas-Peucker and, where that would make rings cross or touch,
 * simplifies those rings again with a smaller tolerance. The origin's yaw is applied.
 *
 * @param source names the grid in errors (a file path or a topic)
 * @param report when not null, receives what was done
 * @throws MapError (file = @p source) for an invalid grid, no free cell, a seed outside the
 *         grid or in a wall, or options out of range.
 */
PolygonMap gridToPolygon(const OccupancyGrid& grid, const GridConversionOptions& options = {},
                         const std::string& source = "<grid>", GridConversionReport* report = nullptr);

/**
 * @brief Loads any map file: `.poly` (loadPolyFile) or a map_server `.yaml` / `.yml`
 *        (loadOccupancyGridYaml, then gridToPolygon with @p options).
 * @throws MapError naming the file and the problem (also for an unknown extension).
 */
PolygonMap loadMapFile(const std::string& path, const GridConversionOptions& options = {},
                       GridConversionReport* report = nullptr);

/// Options of rasterize().
struct RasterizeOptions
{
  double resolution = 0.05;   ///< cell edge [m], > 0
  double margin = 0.5;        ///< unknown border around the map's bounds [m], >= 0
  double wall_thickness = 0.15;  ///< non-free cells this close to free space are occupied [m]
  double boundary_noise = 0.0;   ///< probability a free cell touching a wall turns occupied, [0, 1]
  int specks = 0;             ///< small random occupied blobs (1 to 2 cells a side) in free space
  int islands = 0;            ///< small free blobs in the unknown area outside the walls
  std::uint64_t seed = 1;     ///< random seed (same seed, same grid)
};

/**
 * @brief Rasterises a polygon map like a SLAM map: free cells (centre inside the free space)
 *        0, cells within wall_thickness of free space 100, everything else -1, then the
 *        requested noise, specks and islands. Grid axes are the map's axes (yaw 0).
 * @throws std::invalid_argument naming the option out of range, or for an empty map.
 */
OccupancyGrid rasterize(const PolygonMap& map, const RasterizeOptions& options);

/**
 * @brief Writes a PNG preview: the grid in grey (free white, occupied black, unknown grey),
 *        the polygon's outer ring in blue and its holes in red drawn over it. Small grids are
 *        scaled up (an integer factor, at most 8) to about 1200 pixels along the longer side.
 * @throws std::runtime_error naming the file when it cannot be written.
 */
void writePreviewPng(const std::string& path, const OccupancyGrid& grid, const PolygonMap& map);

}  // namespace core
}  // namespace fdml_localization
