// rostest of occupancy-grid maps in the fdml_localizer node: a node with ~use_map_topic answers
// "no map yet" until the test publishes a latched nav_msgs/OccupancyGrid (the test room,
// rasterised in a rotated grid frame), then localizes on readings simulated on the original
// polygon; an all-occupied grid is rejected and the map stays; a new map replaces it. A second
// node loads a map_server YAML as ~map_file.
#include "node_test_scene.h"

#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/ros/conversions.h"
#include "message_collector.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <fdml_localization/Localize.h>
#include <fdml_localization/Relocalize.h>
#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <visualization_msgs/MarkerArray.h>

#include <cmath>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace test
{
namespace
{
// A converted grid's walls are good to about a cell (5 cm): the estimate is a little looser
// than on the polygon itself.
constexpr double kPositionTolerance = 0.08;                  // [m]
constexpr double kAngleTolerance = 3.0 * core::kPi / 180.0;  // [rad]
constexpr double kMapTimeout = 120.0;                        // [s] conversion and tables on a loaded machine

/// The grid's frame in the map: rotated and shifted, so the node must apply the origin's yaw.
const core::Pose2 kGridFrame(0.31, -0.17, 0.35);

/// @p map translated by @p shift [m].
core::PolygonMap shifted(const core::PolygonMap& map, const core::Vec2& shift)
{
  std::vector<core::Ring> rings = map.rings();
  for (core::Ring& ring : rings)
  {
    for (core::Vec2& p : ring)
    {
      p += shift;
    }
  }
  return core::PolygonMap::fromRings(rings, "shifted test room");
}

/// @p map rasterised at 5 cm in the frame kGridFrame: the grid's origin carries the rotation.
nav_msgs::OccupancyGrid gridMessage(const core::PolygonMap& map)
{
  const core::Pose2 to_local = core::inverse(kGridFrame);
  std::vector<core::Ring> rings = map.rings();
  for (core::Ring& ring : rings)
  {
    for (core::Vec2& p : ring)
    {
      p = core::transformPoint(to_local, p);
    }
  }
  core::RasterizeOptions options;
  options.resolution = 0.05;
  options.margin = 0.3;
  options.seed = 5;
  core::OccupancyGrid grid = core::rasterize(core::PolygonMap::fromRings(rings, "local test room"), options);
  grid.origin = core::compose(kGridFrame, grid.origin);
  return toOccupancyGridMsg(grid, "map", ros::Time::now());
}

/// The map publisher, latched, alive for the whole test run.
ros::Publisher& mapPublisher()
{
  static ros::NodeHandle nh;
  static ros::Publisher publisher = nh.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  return publisher;
}

fdml_localization::Localize localizeCall(const std::string& node, const TurningScene& scene, int first)
{
  ros::NodeHandle nh;
  ros::ServiceClient client = nh.serviceClient<fdml_localization::Localize>(node + "/localize");
  EXPECT_TRUE(client.waitForExistence(ros::Duration(60.0))) << node << "/localize never appeared";
  fdml_localization::Localize srv;
  srv.request.readings = scene.readings(first, scene.k);
  EXPECT_TRUE(client.call(srv)) << node << "/localize";
  return srv;
}

/// Calls ~localize until @p done holds for the response (false on timeout); returns the last one.
bool localizeUntil(const std::string& node, const TurningScene& scene, int first,
                   const std::function<bool(const fdml_localization::Localize::Response&)>& done,
                   fdml_localization::Localize::Response* last)
{
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kMapTimeout);
  while (ros::ok() && ros::WallTime::now() < deadline)
  {
    *last = localizeCall(node, scene, first).response;
    if (done(*last))
    {
      return true;
    }
    ros::WallDuration(0.2).sleep();  // polling a condition with a deadline, not synchronisation
  }
  return false;
}

bool near(const fdml_localization::Localize::Response& response, const core::Pose2& truth)
{
  if (!response.success || response.result.candidates.empty())
  {
    return false;
  }
  const core::Pose2 best = fromPoseMsg(response.result.candidates.front().pose);
  return (best.position() - truth.position()).norm() < kPositionTolerance &&
         std::fabs(core::angleDiff(best.theta, truth.theta)) < kAngleTolerance;
}

void expectLocalized(const fdml_localization::Localize::Response& response, const TurningScene& scene, int first,
                     const core::Vec2& shift, const std::string& what)
{
  ASSERT_TRUE(response.success) << what << ": " << response.message;
  ASSERT_FALSE(response.result.candidates.empty()) << what << ": " << response.message;
  const auto& best = response.result.candidates.front();
  const core::Pose2 estimate = fromPoseMsg(best.pose);
  core::Pose2 truth = scene.baseInMap(first);
  truth.x += shift.x();
  truth.y += shift.y();
  EXPECT_LT((estimate.position() - truth.position()).norm(), kPositionTolerance)
      << what << ": (" << estimate.x << ", " << estimate.y << ") vs (" << truth.x << ", " << truth.y << ")";
  EXPECT_LT(std::fabs(core::angleDiff(estimate.theta, truth.theta)), kAngleTolerance)
      << what << ": theta " << estimate.theta << " vs " << truth.theta;
  ASSERT_EQ(best.inlier_mask.size(), static_cast<std::size_t>(scene.k)) << what;
  for (int i = 0; i < scene.k; ++i)
  {
    EXPECT_EQ(static_cast<bool>(best.inlier_mask[static_cast<std::size_t>(i)]), !scene.occluded(first + i))
        << what << ": reading " << i;
  }
}

/// The value of @p key in a diagnostic status holding it, "" when none does.
std::string diagnosticValue(const diagnostic_msgs::DiagnosticArray& msg, const std::string& key)
{
  for (const auto& status : msg.status)
  {
    for (const auto& kv : status.values)
    {
      if (kv.key == key)
      {
        return kv.value;
      }
    }
  }
  return "";
}

TEST(LocalizerMapTopic, NoMapYetUntilAMapArrives)
{
  ros::NodeHandle nh;
  TurningScene scene;
  const fdml_localization::Localize localize = localizeCall("fdml_localizer_topic", scene, 0);
  EXPECT_FALSE(localize.response.success);
  EXPECT_NE(localize.response.message.find("no map yet"), std::string::npos) << localize.response.message;

  ros::ServiceClient relocalize = nh.serviceClient<fdml_localization::Relocalize>("fdml_localizer_topic/relocalize");
  ASSERT_TRUE(relocalize.waitForExistence(ros::Duration(60.0)));
  fdml_localization::Relocalize srv;
  srv.request.timeout = 30.0;  // must answer at once, not wait for readings
  const ros::WallTime start = ros::WallTime::now();
  ASSERT_TRUE(relocalize.call(srv));
  EXPECT_FALSE(srv.response.success);
  EXPECT_NE(srv.response.message.find("no map yet"), std::string::npos) << srv.response.message;
  EXPECT_LT((ros::WallTime::now() - start).toSec(), 25.0) << "~relocalize waited for readings without a map";
}

TEST(LocalizerMapTopic, LocalizesOnAGridFromTheTopic)
{
  ros::NodeHandle nh;
  TurningScene scene;
  Collector<visualization_msgs::MarkerArray> markers(nh, "fdml_localizer_topic/map_markers");
  mapPublisher().publish(gridMessage(scene.map->map()));

  fdml_localization::Localize::Response response;
  const bool answered = localizeUntil(
      "fdml_localizer_topic", scene, 0,
      [](const fdml_localization::Localize::Response& r) { return r.message.find("no map yet") == std::string::npos; },
      &response);
  ASSERT_TRUE(answered) << "the map never came into use: " << response.message;
  expectLocalized(response, scene, 0, core::Vec2::Zero(), "map from the topic, readings 0..9");
  expectLocalized(localizeCall("fdml_localizer_topic", scene, 4).response, scene, 4, core::Vec2::Zero(),
                  "map from the topic, readings 4..13");

  // The markers of the converted map (rotated into the map frame: walls near x = 0 and x = 6).
  EXPECT_TRUE(markers.waitFor(
      [](const visualization_msgs::MarkerArray& msg) {
        double min_x = 1e9;
        double max_x = -1e9;
        for (const auto& marker : msg.markers)
        {
          for (const auto& p : marker.points)
          {
            min_x = std::min(min_x, p.x);
            max_x = std::max(max_x, p.x);
          }
        }
        return std::fabs(min_x) < 0.1 && std::fabs(max_x - 6.0) < 0.1;
      },
      30.0))
      << "no map markers of the converted map";
}

TEST(LocalizerMapTopic, ABadGridIsRejectedAndTheMapStays)
{
  ros::NodeHandle nh;
  TurningScene scene;
  Collector<diagnostic_msgs::DiagnosticArray> diagnostics(nh, "/diagnostics");
  core::OccupancyGrid walls;
  walls.width = 40;
  walls.height = 30;
  walls.cells.assign(40 * 30, 100);  // all occupied: no free space
  mapPublisher().publish(toOccupancyGridMsg(walls, "map", ros::Time::now()));

  EXPECT_TRUE(diagnostics.waitFor(
      [](const diagnostic_msgs::DiagnosticArray& msg) {
        return diagnosticValue(msg, "maps rejected") == "1" &&
               diagnosticValue(msg, "last map error").find("free") != std::string::npos;
      },
      60.0))
      << "the diagnostics never counted the all-occupied map with its reason";
  expectLocalized(localizeCall("fdml_localizer_topic", scene, 0).response, scene, 0, core::Vec2::Zero(),
                  "after a rejected map");
}

TEST(LocalizerMapTopic, ANewGridReplacesTheMap)
{
  TurningScene scene;
  const core::Vec2 shift(1.0, 0.5);
  mapPublisher().publish(gridMessage(shifted(scene.map->map(), shift)));
  core::Pose2 truth = scene.baseInMap(0);
  truth.x += shift.x();
  truth.y += shift.y();
  fdml_localization::Localize::Response response;
  const bool moved = localizeUntil(
      "fdml_localizer_topic", scene, 0,
      [&truth](const fdml_localization::Localize::Response& r) { return near(r, truth); }, &response);
  EXPECT_TRUE(moved) << "the answer never moved with the new map: " << response.message;
  expectLocalized(response, scene, 0, shift, "after the map was replaced");
}

TEST(LocalizerMapTopic, LocalizesOnAMapServerYamlFile)
{
  TurningScene scene;
  // The map is loaded before the services appear: the first call is answered on it.
  expectLocalized(localizeCall("fdml_localizer_yaml", scene, 0).response, scene, 0, core::Vec2::Zero(),
                  "map_server YAML ~map_file");
}

}  // namespace
}  // namespace test
}  // namespace fdml_localization

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_localizer_map_topic");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
