// Every shipped YAML passes the validation of the node that reads it (see config_check.test).
#include "fdml_localization/simulation/scenario.h"
#include "fdml_localization/ros/param_utils.h"
#include "fdml_localization/ros/params.h"

#include <ros/ros.h>

#include <gtest/gtest.h>

#include <dirent.h>

#include <string>
#include <vector>

namespace fdml_localization
{
namespace
{
std::vector<std::string> yamlStems(const std::string& folder)
{
  std::vector<std::string> stems;
  DIR* dir = opendir(folder.c_str());
  if (dir == nullptr)
  {
    return stems;
  }
  while (const dirent* entry = readdir(dir))
  {
    const std::string name = entry->d_name;
    if (name.size() > 5 && name.compare(name.size() - 5, 5, ".yaml") == 0)
    {
      stems.push_back(name.substr(0, name.size() - 5));
    }
  }
  closedir(dir);
  return stems;
}

std::string joined(const std::vector<std::string>& errors)
{
  std::string text;
  for (const std::string& e : errors)
  {
    text += "\n  " + e;
  }
  return text;
}
}  // namespace

TEST(ConfigCheck, LocalizerYamlPassesValidation)
{
  const ros::NodeHandle nh("config_check/localizer");
  ASSERT_TRUE(nh.hasParam("measurements_per_batch")) << "config/localizer.yaml was not loaded";
  Params params = loadParams(nh);
  params.map_file = std::string(FDML_SOURCE_DIR) + "/maps/office.poly";  // given by the launch file
  const std::vector<std::string> errors = validate(params);
  EXPECT_TRUE(errors.empty()) << joined(errors);
}

TEST(ConfigCheck, EveryScenarioParses)
{
  const std::vector<std::string> stems = yamlStems(std::string(FDML_SOURCE_DIR) + "/config/scenarios");
  ASSERT_FALSE(stems.empty());
  for (const std::string& stem : stems)
  {
    const ros::NodeHandle nh("config_check/scenarios/" + stem);
    ASSERT_TRUE(nh.hasParam("map_file")) << "config/scenarios/" << stem << ".yaml is not loaded by config_check.test";
    core::ScenarioConfig config;
    const std::vector<std::string> errors = core::parseScenario(readParamTree(nh), &config);
    EXPECT_TRUE(errors.empty()) << stem << ":" << joined(errors);
  }
}

TEST(ConfigCheck, NoOtherYamlInConfig)
{
  const std::vector<std::string> top = yamlStems(std::string(FDML_SOURCE_DIR) + "/config");
  ASSERT_EQ(top.size(), 1u) << "a YAML in config/ that config_check.test does not validate";
  EXPECT_EQ(top.front(), "localizer");
}

}  // namespace fdml_localization

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_config_check");
  return RUN_ALL_TESTS();
}
