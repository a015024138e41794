// Tests of the ROS conversion helpers and parameter utilities (no roscore needed): the
// simulator's, then the localizer node's (round trips and REP-117 semantics).
#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/markers.h"
#include "fdml_localization/ros/param_utils.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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

TEST(Conversions, MarkersCarryTheGeometry)
{
  std::vector<core::Ring> rings = { { Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(0, 1) } };
  const core::PolygonMap map = core::PolygonMap::fromRings(rings, "box");
  const auto walls = fl::mapMarkers(map, "map", ros::Time(1.0));
  ASSERT_EQ(walls.markers.size(), 1u);
  EXPECT_EQ(walls.markers[0].points.size(), 2 * map.edges().size());
  const std::vector<core::Obstacle> obstacles = {
    core::Obstacle::disc(Vec2(0.5, 0.5), 0.1), core::Obstacle::polygon({ Vec2(1, 0.2), Vec2(1.3, 0.2), Vec2(1.1, 0.5) })
  };
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

// ---------------------------------------------------------------------------------------------
// Localizer node conversions (issue 6).
// ---------------------------------------------------------------------------------------------

namespace fdml_localization
{
namespace
{
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

void expectPoseNear(const core::Pose2& a, const core::Pose2& b, double tol = 1e-12)
{
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(core::angleDiff(a.theta, b.theta), 0.0, tol);
}

TEST(LocalizerConversions, YawOfUnnormalisedAndBrokenQuaternions)
{
  for (int i = -40; i <= 40; ++i)
  {
    const double yaw = i * 0.1;
    const geometry_msgs::Quaternion q = yawToQuaternion(yaw);
    EXPECT_NEAR(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w, 1.0, 1e-12);
    EXPECT_EQ(q.x, 0.0);
    EXPECT_EQ(q.y, 0.0);
    EXPECT_NEAR(core::angleDiff(quaternionToYaw(q), yaw), 0.0, 1e-12);
    EXPECT_GE(quaternionToYaw(q), -core::kPi);
    EXPECT_LT(quaternionToYaw(q), core::kPi);
  }
  // A non-normalised quaternion of the same rotation gives the same yaw; a zero one gives 0.
  geometry_msgs::Quaternion scaled = yawToQuaternion(0.7);
  scaled.z *= 3.0;
  scaled.w *= 3.0;
  EXPECT_NEAR(quaternionToYaw(scaled), 0.7, 1e-12);
  EXPECT_EQ(quaternionToYaw(geometry_msgs::Quaternion()), 0.0);
  geometry_msgs::Quaternion broken;
  broken.w = kNan;
  EXPECT_EQ(quaternionToYaw(broken), 0.0);
}

TEST(LocalizerConversions, CovarianceEmbedsInXYYaw)
{
  Eigen::Matrix3d covariance;
  covariance << 1.0, 0.2, 0.3, 0.2, 2.0, 0.4, 0.3, 0.4, 3.0;
  const boost::array<double, 36> six = toCovariance6(covariance);
  EXPECT_EQ(six[0], 1.0);
  EXPECT_EQ(six[1], 0.2);
  EXPECT_EQ(six[5], 0.3);
  EXPECT_EQ(six[6 + 1], 2.0);
  EXPECT_EQ(six[6 * 5 + 5], 3.0);
  EXPECT_EQ(six[6 * 5 + 1], 0.4);
  double others = 0.0;
  for (int r = 0; r < 6; ++r)
  {
    for (int c = 0; c < 6; ++c)
    {
      const bool planar = (r == 0 || r == 1 || r == 5) && (c == 0 || c == 1 || c == 5);
      others += planar ? 0.0 : std::fabs(six[static_cast<std::size_t>(r * 6 + c)]);
    }
  }
  EXPECT_EQ(others, 0.0);
  EXPECT_TRUE(fromCovariance6(six).isApprox(covariance, 0.0));
}

TEST(LocalizerConversions, ReadingMessagesRoundTripIncludingNoReturn)
{
  core::Reading reading;
  reading.offset = core::Pose2(0.1, -0.2, 1.5);
  reading.range = 2.5;
  reading.max_range = 4.0;
  core::Reading back = fromReadingMsg(toReadingMsg(reading));
  expectPoseNear(back.offset, reading.offset);
  EXPECT_EQ(back.range, 2.5);
  EXPECT_EQ(back.max_range, 4.0);

  reading.range = core::kInf;
  reading.max_range = core::kInf;
  back = fromReadingMsg(toReadingMsg(reading));
  EXPECT_EQ(back.range, core::kInf);
  EXPECT_EQ(back.max_range, core::kInf);

  std::vector<fdml_localization::Reading> msgs(3, toReadingMsg(reading));
  EXPECT_EQ(fromReadingMsgs(msgs).size(), 3u);
}

TEST(LocalizerConversions, ResultAndCandidateMessages)
{
  core::Result result;
  core::Candidate candidate;
  candidate.pose = core::Pose2(1.0, 2.0, -0.5);
  candidate.inlier_mask = { true, false, true, true };
  candidate.inliers = 3;
  candidate.rms_residual = 0.01;
  result.candidates = { candidate, candidate };
  result.candidates[1].inliers = 2;
  result.readings_used = 4;
  result.min_inliers_used = 3;
  result.times.total = 0.25;
  result.times.polish = 0.125;
  result.truncated = true;
  result.engine = core::Engine::Adaptive;
  result.method = core::Method::Paper;

  const fdml_localization::LocalizationResult msg = toResultMsg(result);
  ASSERT_EQ(msg.candidates.size(), 2u);
  expectPoseNear(fromPoseMsg(msg.candidates[0].pose), candidate.pose);
  EXPECT_EQ(msg.candidates[0].inliers, 3u);
  EXPECT_EQ(msg.candidates[1].inliers, 2u);
  EXPECT_EQ(msg.candidates[0].inlier_mask, std::vector<uint8_t>({ 1, 0, 1, 1 }));
  EXPECT_EQ(msg.candidates[0].rms_residual, 0.01);
  EXPECT_EQ(msg.readings_used, 4u);
  EXPECT_EQ(msg.min_inliers_used, 3u);
  EXPECT_EQ(msg.engine, "adaptive");
  EXPECT_EQ(msg.method, "paper");
  EXPECT_EQ(msg.solve_time, 0.25);
  EXPECT_TRUE(msg.search_truncated);
  ASSERT_EQ(msg.stage_names.size(), msg.stage_times.size());
  bool found_polish = false;
  for (std::size_t i = 0; i < msg.stage_names.size(); ++i)
  {
    if (msg.stage_names[i] == "polish")
    {
      found_polish = true;
      EXPECT_EQ(msg.stage_times[i], 0.125);
    }
  }
  EXPECT_TRUE(found_polish);

  fdml_localization::LocalizationResult with_drops = msg;
  setDropCounts({ { "nan_range", 2 }, { "stamp_backwards", 1 } }, &with_drops);
  EXPECT_EQ(with_drops.drop_reasons, std::vector<std::string>({ "nan_range", "stamp_backwards" }));
  EXPECT_EQ(with_drops.drop_counts, std::vector<uint32_t>({ 2, 1 }));
}

TEST(LocalizerConversions, ReadingMarkersDrawRaysFromThePoseColouredByInlier)
{
  const core::Pose2 pose(1.0, 2.0, 0.5);
  std::vector<core::Reading> readings(3);
  readings[0].offset = core::Pose2(0.1, 0.0, 0.0);
  readings[0].range = 2.0;
  readings[1].offset = core::Pose2(0.0, 0.1, core::kPi / 2);
  readings[1].range = 1.0;
  readings[2].offset = core::Pose2(0.0, 0.0, core::kPi);
  readings[2].range = core::kInf;
  readings[2].max_range = 0.5;
  const visualization_msgs::MarkerArray array =
      readingMarkers(readings, pose, { true, false, true }, "map", ros::Time(5.0), 1.0);
  ASSERT_EQ(array.markers.size(), 3u);
  EXPECT_EQ(array.markers[0].action, visualization_msgs::Marker::DELETEALL);
  const visualization_msgs::Marker& rays = array.markers[1];
  ASSERT_EQ(rays.points.size(), 6u);
  ASSERT_EQ(rays.colors.size(), 6u);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    // Independent computation of the sensor pose q (+) g_i and the ray's end.
    const core::Pose2& g = readings[i].offset;
    const double sx = pose.x + std::cos(pose.theta) * g.x - std::sin(pose.theta) * g.y;
    const double sy = pose.y + std::sin(pose.theta) * g.x + std::cos(pose.theta) * g.y;
    const double length = std::isfinite(readings[i].range) ? readings[i].range : 0.5;
    EXPECT_NEAR(rays.points[2 * i].x, sx, 1e-12);
    EXPECT_NEAR(rays.points[2 * i].y, sy, 1e-12);
    EXPECT_NEAR(rays.points[2 * i + 1].x, sx + length * std::cos(pose.theta + g.theta), 1e-12);
    EXPECT_NEAR(rays.points[2 * i + 1].y, sy + length * std::sin(pose.theta + g.theta), 1e-12);
  }
  EXPECT_GT(rays.colors[0].g, rays.colors[0].r);  // inlier: green
  EXPECT_GT(rays.colors[2].r, rays.colors[2].g);  // outlier: red
  EXPECT_EQ(array.markers[2].points.size(), 2u);  // hit points of the two returns
}

// ---------------------------------------------------------------------------------------------
// nav_msgs/OccupancyGrid <-> core::OccupancyGrid (issue 9).
// ---------------------------------------------------------------------------------------------

TEST(Conversions, OccupancyGridMessageRoundTrip)
{
  core::OccupancyGrid grid;
  grid.width = 7;
  grid.height = 4;
  grid.resolution = 0.25;  // exact in float32
  grid.origin = core::Pose2(-1.5, 2.25, 0.7);
  for (int i = 0; i < grid.width * grid.height; ++i)
  {
    grid.cells.push_back(static_cast<std::int8_t>(i % 3 == 0 ? -1 : (i * 13) % 101));
  }
  const nav_msgs::OccupancyGrid msg = toOccupancyGridMsg(grid, "map", ros::Time(3.0));
  EXPECT_EQ(msg.header.frame_id, "map");
  EXPECT_EQ(msg.header.stamp, ros::Time(3.0));
  EXPECT_EQ(msg.info.width, 7u);
  EXPECT_EQ(msg.info.height, 4u);
  EXPECT_EQ(msg.info.resolution, 0.25f);
  EXPECT_EQ(msg.info.origin.position.x, -1.5);
  EXPECT_EQ(msg.info.origin.position.y, 2.25);
  EXPECT_NEAR(msg.info.origin.orientation.z, std::sin(0.35), 1e-12);
  EXPECT_NEAR(msg.info.origin.orientation.w, std::cos(0.35), 1e-12);
  ASSERT_EQ(msg.data.size(), grid.cells.size());
  for (std::size_t i = 0; i < grid.cells.size(); ++i)
  {
    EXPECT_EQ(msg.data[i], grid.cells[i]) << i;  // same layout: row-major, row 0 at the bottom
  }

  const core::OccupancyGrid back = fromOccupancyGridMsg(msg);
  EXPECT_EQ(back.width, grid.width);
  EXPECT_EQ(back.height, grid.height);
  EXPECT_EQ(back.resolution, grid.resolution);
  EXPECT_EQ(back.origin.x, grid.origin.x);
  EXPECT_EQ(back.origin.y, grid.origin.y);
  EXPECT_NEAR(back.origin.theta, grid.origin.theta, 1e-12);
  EXPECT_EQ(back.cells, grid.cells);
  EXPECT_TRUE(back.validate().empty());
}

TEST(Conversions, OccupancyGridMessageGeometry)
{
  // A message built by hand, as a SLAM node publishes it: cell (ix, iy) is data[iy * width + ix],
  // its centre is origin (+) ((ix + 0.5) res, (iy + 0.5) res) with the origin's yaw applied.
  nav_msgs::OccupancyGrid msg;
  msg.info.width = 3;
  msg.info.height = 2;
  msg.info.resolution = 0.5f;
  msg.info.origin.position.x = 1.0;
  msg.info.origin.position.y = -2.0;
  msg.info.origin.position.z = 0.3;  // ignored
  // A yaw of pi/2 as a non-normalised quaternion (twice the unit one).
  msg.info.origin.orientation.z = 2.0 * std::sin(core::kPi / 4.0);
  msg.info.origin.orientation.w = 2.0 * std::cos(core::kPi / 4.0);
  msg.data = { 0, 100, -1, 0, 0, 50 };
  const core::OccupancyGrid grid = fromOccupancyGridMsg(msg);
  EXPECT_TRUE(grid.validate().empty());
  EXPECT_NEAR(grid.origin.theta, core::kPi / 2.0, 1e-12);
  EXPECT_EQ(grid.at(1, 0), 100);
  EXPECT_EQ(grid.at(2, 0), -1);
  EXPECT_EQ(grid.at(2, 1), 50);
  // Cell (2, 1): local centre (1.25, 0.75) rotated by pi/2 -> (-0.75, 1.25), plus the origin.
  const core::Vec2 centre = grid.cellCentre(2, 1);
  EXPECT_NEAR(centre.x(), 1.0 - 0.75, 1e-12);
  EXPECT_NEAR(centre.y(), -2.0 + 1.25, 1e-12);
  int ix = -1;
  int iy = -1;
  ASSERT_TRUE(grid.cellOf(centre, &ix, &iy));
  EXPECT_EQ(ix, 2);
  EXPECT_EQ(iy, 1);

  // A data array of the wrong size is copied as is and reported by the core's validation.
  msg.data.pop_back();
  const std::vector<std::string> issues = fromOccupancyGridMsg(msg).validate();
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_NE(issues[0].find("width * height"), std::string::npos) << issues[0];
}

}  // namespace
}  // namespace fdml_localization
