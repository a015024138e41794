// The fixture of the simulator rostests: subscribes to every output of fdml_simulator and
// keeps the messages by stamp for independent checks.
#pragma once

#include "fdml_localization/ReadingTruth.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/param_utils.h"

#include <gtest/gtest.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <functional>
#include <map>
#include <memory>

namespace core = fdml_localization::core;
namespace fl = fdml_localization;

constexpr double kWaitSeconds = 30.0;  // wall-clock timeout of every wait

class SimulatorTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    std::string url;
    ASSERT_TRUE(nh_.getParam("/fdml_simulator/map_file", url));
    std::string error;
    const std::string path = fl::resolveResourcePath(url, &error);
    ASSERT_FALSE(path.empty()) << error;
    caster_ = std::make_shared<core::MapRayCaster>(core::loadPolyFile(path));
    range_sub_ = nh_.subscribe("range", 10000, &SimulatorTest::onRange, this);
    truth_sub_ = nh_.subscribe("ground_truth_readings", 10000, &SimulatorTest::onTruth, this);
    odom_sub_ = nh_.subscribe("odom", 10000, &SimulatorTest::onOdom, this);
    gt_sub_ = nh_.subscribe("ground_truth", 10000, &SimulatorTest::onGroundTruth, this);
    markers_sub_ = nh_.subscribe("obstacle_markers", 10000, &SimulatorTest::onMarkers, this);
    scan_sub_ = nh_.subscribe<sensor_msgs::LaserScan>(
        "scan", 1000, [this](const sensor_msgs::LaserScan::ConstPtr& msg) { scans_.push_back(*msg); });
    grid_sub_ = nh_.subscribe<nav_msgs::OccupancyGrid>(
        "map", 1, [this](const nav_msgs::OccupancyGrid::ConstPtr& msg) { grids_.push_back(*msg); });
    tf_buffer_ = std::make_unique<tf2_ros::Buffer>();
    tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_buffer_);
  }

  /// Spins until @p done or the wall-clock timeout; returns done().
  bool waitFor(const std::function<bool()>& done, double seconds = kWaitSeconds)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(seconds);
    while (ros::ok() && !done() && ros::WallTime::now() < deadline)
    {
      ros::spinOnce();
      ros::WallDuration(0.002).sleep();
    }
    return done();
  }

  /// The mounting of a sensor frame on the base, from the static tf.
  core::Pose2 mount(const std::string& frame)
  {
    auto it = mounts_.find(frame);
    if (it != mounts_.end())
    {
      return it->second;
    }
    std::string error;
    const bool found = waitFor([&]() { return tf_buffer_->canTransform("base_link", frame, ros::Time(0), &error); });
    EXPECT_TRUE(found) << "no tf base_link -> " << frame << ": " << error;
    if (!found)
    {
      return core::Pose2();
    }
    const core::Pose2 pose =
        fl::fromTransformMsg(tf_buffer_->lookupTransform("base_link", frame, ros::Time(0)).transform);
    mounts_[frame] = pose;
    return pose;
  }

  void onRange(const sensor_msgs::Range::ConstPtr& msg)
  {
    ranges_.push_back(*msg);
  }
  void onTruth(const fl::ReadingTruth::ConstPtr& msg)
  {
    truths_.push_back(*msg);
  }
  void onOdom(const nav_msgs::Odometry::ConstPtr& msg)
  {
    odom_[msg->header.stamp] = fl::fromPoseMsg(msg->pose.pose);
  }
  void onGroundTruth(const nav_msgs::Odometry::ConstPtr& msg)
  {
    EXPECT_EQ(msg->header.frame_id, "map");
    gt_[msg->header.stamp] = fl::fromPoseMsg(msg->pose.pose);
    gt_order_.push_back(msg->header.stamp);
  }
  void onMarkers(const visualization_msgs::MarkerArray::ConstPtr& msg)
  {
    for (const auto& m : msg->markers)
    {
      if (m.ns == "obstacles" && m.action == visualization_msgs::Marker::ADD)
      {
        obstacles_[m.header.stamp].push_back(m);
      }
    }
  }

  ros::NodeHandle nh_;
  std::shared_ptr<core::MapRayCaster> caster_;
  ros::Subscriber range_sub_, truth_sub_, odom_sub_, gt_sub_, markers_sub_, scan_sub_, grid_sub_;
  std::vector<sensor_msgs::LaserScan> scans_;
  std::vector<nav_msgs::OccupancyGrid> grids_;
  std::unique_ptr<tf2_ros::Buffer> tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;
  std::map<std::string, core::Pose2> mounts_;
  std::vector<sensor_msgs::Range> ranges_;
  std::vector<fl::ReadingTruth> truths_;
  std::map<ros::Time, core::Pose2> odom_;
  std::map<ros::Time, core::Pose2> gt_;
  std::vector<ros::Time> gt_order_;
  std::map<ros::Time, std::vector<visualization_msgs::Marker>> obstacles_;
};
