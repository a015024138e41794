// fdml_localizer: global localization from a few range readings. See localizer_node.h.
#include "fdml_localization/ros/localizer_node.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fdml_localizer");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  return fdml_localization::runLocalizerNode(nh, private_nh);
}
