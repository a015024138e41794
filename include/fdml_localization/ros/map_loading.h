/**
 * @file map_loading.h
 * @brief Loading the node's map: from ~map_file (a .poly file or a map_server .yaml occupancy
 *        grid) or from an occupancy grid received on the map topic. One place for map sources.
 */
#pragma once

#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/geometry/ray_caster.h"

#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdml_localization
{
/// Thrown when the map cannot be found or loaded; what() names the file and the problem.
class MapLoadError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// A loaded map and where it came from.
struct LoadedMap
{
  std::shared_ptr<const core::MapRayCaster> map;  ///< null when there is no map (yet)
  std::string source;                             ///< the file or topic it came from
  /// Cell size [m] of the occupancy grid the map comes from (a grid, or a `.poly` whose header
  /// records it); 0 for a plain polygon file. Tolerances: core::withGridTolerances().
  double grid_resolution = 0.0;
  /// One-line summary of the grid conversion (empty for a polygon file).
  std::string summary;
};

/**
 * @brief Resolves a map location to a file path with resolveResourcePath() (param_utils.h):
 *        "package://PKG/rel/path" through the ROS package path, "file:///abs/path" to
 *        "/abs/path", anything else unchanged.
 * @param parameter names the location in errors
 * @throws MapLoadError when the package is not found or the URI is malformed.
 */
std::string resolveMapPath(const std::string& location, const std::string& parameter = "~map_file");

/**
 * @brief Loads the map named by @p location (see resolveMapPath()) with io::readMapFile():
 *        a `.poly` file, or a map_server `.yaml` / `.yml` converted with @p options.
 * @throws MapLoadError naming ~map_file, the file (the image for a missing image), the line
 *         when known, and the problem.
 */
LoadedMap loadMapFromFile(const std::string& location, const core::GridConversionOptions& options = {});

/**
 * @brief The search region named by ~search_region (core::LocalizerOptions::search_region):
 *        any map file, as for ~map_file; @p seed ([x, y] [m], or empty) picks a grid's free
 *        region. Null for an empty @p location.
 * @throws MapLoadError naming ~search_region, the file and the problem
 */
std::shared_ptr<const core::MapRayCaster> loadSearchRegionFile(const std::string& location,
                                                               const std::vector<double>& seed);

/// loadMapFromFile() with the default conversion options, returning the map only.
std::shared_ptr<const core::MapRayCaster> loadMap(const std::string& location);

/**
 * @brief Converts an occupancy grid (from a file or a topic) into the node's map.
 * @param source names the grid in errors and in the summary (a file path or a topic)
 * @throws MapLoadError naming @p source and the problem (an invalid grid, no free cell, a seed
 *         point outside the grid or in a wall, ...).
 */
LoadedMap mapFromGrid(const core::OccupancyGrid& grid, const core::GridConversionOptions& options,
                      const std::string& source);

/// The one-line summary of a conversion (cells, regions, holes kept and dropped, vertices).
std::string describeConversion(const core::OccupancyGrid& grid, const core::GridConversionReport& report);

}  // namespace fdml_localization
