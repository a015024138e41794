/**
 * @file map_files.h
 * @brief Map files on disk: map_server YAML + image occupancy grids (read with yaml-cpp and
 *        stb_image), PGM and preview PNG output, and one loader for every map file type.
 *        ROS-free, but kept out of the core library so that the core links nothing beyond
 *        Eigen, OpenMP and Boost headers: link fdml_localization_map_io to use these.
 */
#pragma once

#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/grid/occupancy_grid.h"
#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/core/map/polygon_map.h"

#include <memory>
#include <string>

namespace fdml_localization
{
namespace io
{
/**
 * @brief Reads a map_server YAML file. Required keys: image, resolution, origin,
 *        occupied_thresh, free_thresh, negate (as map_server requires); optional: mode.
 * @throws core::MapError naming the file, the line when known, the key and the problem.
 */
core::MapYaml loadMapYamlFile(const std::string& path);

/// Loads a map_server map (YAML + image). @throws core::MapError naming the file and the problem.
core::OccupancyGrid loadOccupancyGridYaml(const std::string& yaml_path);

/**
 * @brief Writes the grid as a binary PGM the way map_saver does: free (0) -> 254,
 *        occupied (>= 65) -> 0, anything else -> 205 (unknown), top row first.
 * @throws std::runtime_error naming the file when it cannot be written.
 */
void writePgm(const std::string& path, const core::OccupancyGrid& grid);

/**
 * @brief Saves the grid as a map_server map: @p yaml_path plus a PGM beside it (same stem),
 *        trinary mode, occupied_thresh 0.65, free_thresh 0.196, negate 0.
 * @throws std::runtime_error naming the file when it cannot be written.
 */
void saveOccupancyGridYaml(const std::string& yaml_path, const core::OccupancyGrid& grid);

/// A map file as readMapFile() loads it.
struct MapFile
{
  core::PolygonMap map;
  /// Cell size [m] of the occupancy grid the map comes from (a map_server YAML, or a `.poly`
  /// whose header records it: core::cellSizeHeader()); 0 for a plain polygon map. Give it to
  /// core::withGridTolerances().
  double cell_size = 0.0;
  core::OccupancyGrid grid;           ///< the grid read (a YAML only; empty otherwise)
  core::GridConversionReport report;  ///< what its conversion did (a YAML only)
};

/**
 * @brief Loads any map file, the one loader every tool and node uses: `.poly` (loadPolyFile,
 *        plus its cell-size header) or a map_server `.yaml` / `.yml` (loadOccupancyGridYaml,
 *        then gridToPolygon with @p options).
 * @throws core::MapError naming the file and the problem (also for an unknown extension).
 */
MapFile readMapFile(const std::string& path, const core::GridConversionOptions& options = {});

/// readMapFile(), the map only (@p report, when not null, receives the conversion's report).
core::PolygonMap loadMapFile(const std::string& path, const core::GridConversionOptions& options = {},
                             core::GridConversionReport* report = nullptr);

/**
 * @brief A search region (core::LocalizerOptions::search_region) from any map file, loaded as
 *        readMapFile() loads maps: the free space of a `.poly`, or of a map_server YAML grid
 *        (with @p seed [m], the free region holding that point; otherwise the largest). A copy of
 *        the map's image with everything the robot never reaches painted black makes one.
 * @throws core::MapError naming the file and the problem
 */
std::shared_ptr<const core::MapRayCaster> loadSearchRegion(const std::string& path, const core::Vec2* seed = nullptr);

/**
 * @brief Writes a PNG preview: the grid in grey (free white, occupied black, unknown grey),
 *        the polygon's outer ring in blue and its holes in red drawn over it. Small grids are
 *        scaled up (an integer factor, at most 8) to about 1200 pixels along the longer side.
 * @throws std::runtime_error naming the file when it cannot be written.
 */
void writePreviewPng(const std::string& path, const core::OccupancyGrid& grid, const core::PolygonMap& map);

}  // namespace io
}  // namespace fdml_localization
