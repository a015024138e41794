#include "fdml_localization/ros/map_loading.h"

#include "fdml_localization/core/map_io.h"
#include "fdml_localization/ros/param_utils.h"

#include <fstream>

namespace fdml_localization
{
std::string resolveMapPath(const std::string& location)
{
  std::string error;
  const std::string path = resolveResourcePath(location, &error);
  if (!error.empty())
  {
    throw MapLoadError("~map_file \"" + location + "\": " + error);
  }
  return path;
}

std::shared_ptr<const core::MapRayCaster> loadMap(const std::string& location)
{
  const std::string path = resolveMapPath(location);
  if (!std::ifstream(path).good())
  {
    throw MapLoadError("~map_file \"" + location + "\": cannot open \"" + path + "\" (missing or unreadable)");
  }
  const std::string extension = path.size() >= 5 ? path.substr(path.size() - 5) : "";
  if (extension != ".poly")
  {
    throw MapLoadError("~map_file \"" + location + "\": unsupported map format (expected a .poly file)");
  }
  try
  {
    return std::make_shared<const core::MapRayCaster>(core::loadPolyFile(path));
  }
  catch (const std::exception& error)
  {
    throw MapLoadError(std::string("~map_file: ") + error.what());
  }
}

}  // namespace fdml_localization
