#include "fdml_localization/ros/map_loading.h"

#include "fdml_localization/core/map_io.h"

#include <ros/package.h>

#include <fstream>

namespace fdml_localization
{
std::string resolveMapPath(const std::string& location)
{
  const std::string package_scheme = "package://";
  const std::string file_scheme = "file://";
  if (location.compare(0, file_scheme.size(), file_scheme) == 0)
  {
    return location.substr(file_scheme.size());
  }
  if (location.compare(0, package_scheme.size(), package_scheme) != 0)
  {
    return location;
  }
  const std::string rest = location.substr(package_scheme.size());
  const std::size_t slash = rest.find('/');
  if (slash == std::string::npos || slash == 0 || slash + 1 >= rest.size())
  {
    throw MapLoadError("~map_file \"" + location + "\": expected package://PACKAGE/relative/path");
  }
  const std::string package = rest.substr(0, slash);
  const std::string package_path = ros::package::getPath(package);
  if (package_path.empty())
  {
    throw MapLoadError("~map_file \"" + location + "\": package \"" + package +
                       "\" not found on ROS_PACKAGE_PATH (source the workspace's setup.bash)");
  }
  return package_path + "/" + rest.substr(slash + 1);
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
