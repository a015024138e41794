// Tests of the ROS conversion helpers and parameter utilities (no roscore needed).
#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/param_utils.h"

#include <gtest/gtest.h>

#include <cmath>

namespace core = fdml_localization::core;
namespace fl = fdml_localization;
using core::Vec2;

TEST(Conversions, YawQuaternionRoundTrip)
{
  for (double yaw = -3.1; yaw < 3.14; yaw += 0.37)
  {
    const geometry_msgs::Quaternion q = fl::yawToQuaternion(yaw);
    EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 1.0, 1e-12);
    EXPECT_NEAR(fl::quaternionToYaw(q), yaw, 1e-12);
  }
  // A rotation of pi about +z given with w < 0 is the same yaw.
  geometry_msgs::Quaternion q;
  q.z = -1.0;
  q.w = 0.0;
  EXPECT_NEAR(std::abs(fl::quaternionToYaw(q)), core::kPi, 1e-12);
  geometry_msgs::Quaternion zero;
  zero.w = 0.0;
  EXPECT_EQ(fl::quaternionToYaw(zero), 0.0);
}

TEST(Conversions, PosesAndTransformsRoundTrip)
{
  const core::Pose2 pose(1.5, -2.25, 2.5);
  const core::Pose2 a = fl::fromPoseMsg(fl::toPoseMsg(pose));
  const core::Pose2 b = fl::fromTransformMsg(fl::toTransformMsg(pose));
  const core::Pose2 c = fl::fromPose2D(fl::toPose2D(pose));
  for (const core::Pose2& p : { a, b, c })
  {
    EXPECT_NEAR(p.x, pose.x, 1e-12);
    EXPECT_NEAR(p.y, pose.y, 1e-12);
    EXPECT_NEAR(p.theta, pose.theta, 1e-12);
  }
  geometry_msgs::Pose2D unwrapped;
  unwrapped.theta = 3.0 * core::kPi / 2.0;
  EXPECT_NEAR(fl::fromPose2D(unwrapped).theta, -core::kPi / 2.0, 1e-12);
}

TEST(Conversions, OccupancyGridMatchesTheMap)
{
  std::vector<core::Ring> rings = { { Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(0, 1) },
                                    { Vec2(0.8, 0.3), Vec2(1.2, 0.3), Vec2(1.2, 0.7), Vec2(0.8, 0.7) } };
  core::MapRayCaster caster(core::PolygonMap::fromRings(rings, "grid_room"));
  const double res = 0.05;
  const nav_msgs::OccupancyGrid grid = fl::toOccupancyGrid(caster, res, "map", ros::Time(1.0));
  ASSERT_EQ(grid.data.size(), static_cast<std::size_t>(grid.info.width) * grid.info.height);
  EXPECT_EQ(grid.header.frame_id, "map");
  auto cell = [&](double x, double y) {
    const int col = static_cast<int>(std::floor((x - grid.info.origin.position.x) / res));
    const int row = static_cast<int>(std::floor((y - grid.info.origin.position.y) / res));
    return grid.data[static_cast<std::size_t>(row) * grid.info.width + static_cast<std::size_t>(col)];
  };
  EXPECT_EQ(cell(0.4, 0.5), 0);     // free
  EXPECT_EQ(cell(1.0, 0.5), 100);   // inside the hole
  EXPECT_EQ(cell(0.8, 0.5), 100);   // on the hole's wall
  EXPECT_EQ(cell(-0.08, 0.5), -1);  // outside the map
  int free_cells = 0;
  for (std::int8_t v : grid.data)
  {
    free_cells += v == 0 ? 1 : 0;
  }
  // Free area 2 - 0.16 = 1.84 m^2, less the cells the walls (7.6 m) touch on either side.
  EXPECT_GT(free_cells * res * res, 1.84 - 2.0 * 7.6 * res);
  EXPECT_LT(free_cells * res * res, 1.84);
  EXPECT_THROW(fl::toOccupancyGrid(caster, 0.0, "map", ros::Time(1.0)), std::invalid_argument);
}

TEST(Conversions, MarkersCarryTheGeometry)
{
  std::vector<core::Ring> rings = { { Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(0, 1) } };
  const core::PolygonMap map = core::PolygonMap::fromRings(rings, "box");
  const auto walls = fl::mapMarkers(map, "map", ros::Time(1.0));
  ASSERT_EQ(walls.markers.size(), 1u);
  EXPECT_EQ(walls.markers[0].points.size(), 2 * map.edges().size());
  const std::vector<core::Obstacle> obstacles = { core::Obstacle::disc(Vec2(0.5, 0.5), 0.1),
                                                  core::Obstacle::polygon({ Vec2(1, 0.2), Vec2(1.3, 0.2), Vec2(1.1, 0.5) }) };
  const auto markers = fl::obstacleMarkers(obstacles, "map", ros::Time(1.0), 4);
  ASSERT_EQ(markers.markers.size(), 4u);
  EXPECT_EQ(markers.markers[0].type, visualization_msgs::Marker::CYLINDER);
  EXPECT_DOUBLE_EQ(markers.markers[0].scale.x, 0.2);
  EXPECT_DOUBLE_EQ(markers.markers[0].pose.position.x, 0.5);
  EXPECT_EQ(markers.markers[1].type, visualization_msgs::Marker::LINE_STRIP);
  EXPECT_EQ(markers.markers[1].points.size(), 4u);  // closed
  EXPECT_EQ(markers.markers[2].action, visualization_msgs::Marker::DELETE);
  EXPECT_EQ(markers.markers[3].action, visualization_msgs::Marker::DELETE);
}

TEST(ParamUtils, XmlRpcTreesConvert)
{
  XmlRpc::XmlRpcValue root;
  root["name"] = std::string("x");
  root["count"] = 3;
  root["rate"] = 2.5;
  root["on"] = true;
  root["points"][0][0] = 1.0;
  root["points"][0][1] = 2;
  const core::ParamValue v = fl::fromXmlRpc(root);
  ASSERT_TRUE(v.isMap());
  EXPECT_EQ(v.find("name")->asString(), "x");
  EXPECT_EQ(v.find("count")->asInt(), 3);
  EXPECT_DOUBLE_EQ(v.find("rate")->asDouble(), 2.5);
  EXPECT_TRUE(v.find("on")->asBool());
  ASSERT_TRUE(v.find("points")->isList());
  EXPECT_DOUBLE_EQ(v.find("points")->items()[0].items()[1].asDouble(), 2.0);
}

TEST(ParamUtils, ResourcePathsResolve)
{
  std::string error;
  EXPECT_EQ(fl::resolveResourcePath("/a/b.poly", &error), "/a/b.poly");
  EXPECT_EQ(fl::resolveResourcePath("file:///a/b.poly", &error), "/a/b.poly");
  EXPECT_EQ(fl::resolveResourcePath("package://", &error), "");
  EXPECT_NE(error.find("package://PACKAGE/PATH"), std::string::npos);
  error.clear();
  EXPECT_EQ(fl::resolveResourcePath("package://no_such_package_fdml/x.poly", &error), "");
  EXPECT_NE(error.find("no_such_package_fdml"), std::string::npos);
}
