// The simulator node's frame checks (no roscore): an odometry or map frame equal to the base
// frame is refused, naming both parameters.
#include "fdml_localization/ros/simulator_node.h"

#include <gtest/gtest.h>

namespace fdml_localization
{
namespace
{
TEST(SimulatorFrames, OdometryOrMapFrameEqualToTheBaseIsRefusedNamingBoth)
{
  core::FramesConfig frames;
  EXPECT_TRUE(simulatorFrameErrors(frames).empty());

  frames.odom = frames.base;
  std::vector<std::string> errors = simulatorFrameErrors(frames);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("frames.odom"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("frames.base"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("\"base_link\""), std::string::npos) << errors[0];

  frames = core::FramesConfig();
  frames.map = "robot";
  frames.base = "robot";
  errors = simulatorFrameErrors(frames);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("frames.map"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("frames.base"), std::string::npos) << errors[0];
}

}  // namespace
}  // namespace fdml_localization
