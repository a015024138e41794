/**
 * @file grid_to_polygon.h
 * @brief Occupancy grid -> polygon with holes (the map the localizer needs).
 */
#pragma once

#include "fdml_localization/core/map/grid/occupancy_grid.h"
#include "fdml_localization/core/map/polygon_map.h"

#include <cstdint>
#include <string>

namespace fdml_localization
{
namespace core
{
/// Where gridToPolygon() puts a wall between a free cell and a wall cell.
enum class GridWalls
{
  /// Through the boundary wall cells (1/16 cell short of their centres): where a range sensor
  /// measures the wall on average when the grid was made by ray casting (a SLAM map: the cell
  /// holding each laser hit is occupied, the cells the ray crossed are free).
  Measured,
  /// On the free cells' edges: for grids whose free cells are those with their centre in free
  /// space (a floor plan rasterised by cell centres).
  CellEdges
};

/// Parses "measured" / "cell_edges"; throws std::invalid_argument otherwise.
GridWalls parseGridWalls(const std::string& text);
const char* toString(GridWalls walls);

/// Options of gridToPolygon().
struct GridConversionOptions
{
  /// Where the walls go (see GridWalls).
  GridWalls walls = GridWalls::Measured;
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
 * through the boundary wall cells (GridWalls::Measured) or along the cell edges (CellEdges: so
 * before simplification a ray meets the polygon where it meets the first non-free cell), see
 * traceRegionBoundaries(); where two wall cells touch only at a corner the wall stays closed.
 * Drops holes under min_area (the area of the hole's cells, whatever options.walls),
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

}  // namespace core
}  // namespace fdml_localization
