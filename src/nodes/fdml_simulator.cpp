// fdml_simulator: a robot with range sensors among moving obstacles (see ros/simulator_node.h).
#include "fdml_localization/ros/simulator_node.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fdml_simulator");
  fdml_localization::SimulatorNode node(ros::NodeHandle(), ros::NodeHandle("~"));
  std::vector<std::string> errors;
  if (!node.init(&errors))
  {
    for (const std::string& e : errors)
    {
      ROS_FATAL("fdml_simulator: %s", e.c_str());
    }
    return 1;
  }
  ros::spin();
  return 0;
}
