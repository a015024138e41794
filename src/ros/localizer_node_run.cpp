// The fdml_localizer process: parameters, map, node (main() only calls runLocalizerNode()).
#include "fdml_localization/ros/localizer_node.h"
#include "fdml_localization/ros/map_loading.h"

namespace fdml_localization
{
int runLocalizerNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
{
  const Params params = loadParams(private_nh);
  const std::vector<std::string> errors = validate(params);
  for (const std::string& error : errors)
  {
    ROS_FATAL("fdml_localizer: invalid parameter: %s", error.c_str());
  }
  if (!errors.empty())
  {
    return 2;
  }
  ROS_INFO_STREAM(describe(params));
  try
  {
    LoadedMap map;
    if (!params.map_file.empty())
    {
      map = loadMapFromFile(params.map_file, toGridOptions(params));
    }
    LocalizerNode node(nh, private_nh, params, map);
    ros::spin();
  }
  catch (const std::exception& error)
  {
    ROS_FATAL("fdml_localizer: %s", error.what());
    return 1;
  }
  return 0;
}

}  // namespace fdml_localization
