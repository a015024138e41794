// fdml_localizer: global localization from a few range readings. See localizer_node.h.
#include "fdml_localization/ros/localizer_node.h"
#include "fdml_localization/ros/map_loading.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fdml_localizer");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  const fdml_localization::Params params = fdml_localization::loadParams(private_nh);
  const std::vector<std::string> errors = fdml_localization::validate(params);
  for (const std::string& error : errors)
  {
    ROS_FATAL("fdml_localizer: invalid parameter: %s", error.c_str());
  }
  if (!errors.empty())
  {
    return 2;
  }
  ROS_INFO_STREAM(fdml_localization::describe(params));
  try
  {
    fdml_localization::LoadedMap map;
    if (!params.map_file.empty())
    {
      map = fdml_localization::loadMapFromFile(params.map_file, fdml_localization::toGridOptions(params));
    }
    fdml_localization::LocalizerNode node(nh, private_nh, params, map);
    ros::spin();
  }
  catch (const std::exception& error)
  {
    ROS_FATAL("fdml_localizer: %s", error.what());
    return 1;
  }
  return 0;
}
