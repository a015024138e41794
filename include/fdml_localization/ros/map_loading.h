/**
 * @file map_loading.h
 * @brief Loading the node's map from ~map_file: one place to extend with other sources.
 */
#pragma once

#include "fdml_localization/core/ray_caster.h"

#include <memory>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
/// Thrown when the map cannot be found or loaded; what() names the file and the problem.
class MapLoadError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/**
 * @brief Resolves a map location to a file path with resolveResourcePath() (param_utils.h):
 *        "package://PKG/rel/path" through the ROS package path, "file:///abs/path" to
 *        "/abs/path", anything else unchanged.
 * @throws MapLoadError when the package is not found or the URI is malformed.
 */
std::string resolveMapPath(const std::string& location);

/**
 * @brief Loads the map named by @p location (see resolveMapPath()): a `.poly` file.
 *        The single entry point for map loading (other formats plug in here).
 * @throws MapLoadError naming the file, the line when known, and the problem.
 */
std::shared_ptr<const core::MapRayCaster> loadMap(const std::string& location);

}  // namespace fdml_localization
