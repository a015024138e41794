#include "fdml_localization/ros/simulator_node.h"

#include "fdml_localization/ReadingTruth.h"
#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/io/map_files.h"
#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/markers.h"
#include "fdml_localization/ros/param_utils.h"

#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Odometry.h>
#include <rosgraph_msgs/Clock.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace
{
constexpr int kMaxStepsPerTick = 200;
constexpr double kMinTimerPeriod = 1e-3;  // [s]

std::uint8_t hitCode(core::SceneHit::Kind kind)
{
  switch (kind)
  {
    case core::SceneHit::Kind::Map:
      return ReadingTruth::HIT_MAP;
    case core::SceneHit::Kind::Obstacle:
      return ReadingTruth::HIT_OBSTACLE;
    case core::SceneHit::Kind::None:
      break;
  }
  return ReadingTruth::HIT_NONE;
}

nav_msgs::Odometry odometryMsg(const core::Pose2& pose, double linear, double angular, const std::string& frame,
                               const std::string& child, const ros::Time& stamp)
{
  nav_msgs::Odometry msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.child_frame_id = child;
  msg.pose.pose = toPoseMsg(pose);
  msg.twist.twist.linear.x = linear;
  msg.twist.twist.angular.z = angular;
  return msg;
}
}  // namespace

std::vector<std::string> simulatorFrameErrors(const core::FramesConfig& frames)
{
  std::vector<std::string> errors;
  for (const auto& other : { std::make_pair("frames.odom", frames.odom), std::make_pair("frames.map", frames.map) })
  {
    if (other.second == frames.base)
    {
      errors.push_back(std::string(other.first) + " = \"" + other.second + "\" equals frames.base = \"" + frames.base +
                       "\": the two must differ (tf cannot make the base its own parent)");
    }
  }
  return errors;
}

SimulatorNode::SimulatorNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh) : nh_(nh), pnh_(pnh)
{}

bool SimulatorNode::init(std::vector<std::string>* errors)
{
  if (!loadScenario(errors))
  {
    return false;
  }
  start();
  return true;
}

bool SimulatorNode::loadScenario(std::vector<std::string>* errors)
{
  const std::size_t before = errors->size();
  std::vector<std::string> parse_errors = core::parseScenario(readParamTree(pnh_), &config_);
  if (parse_errors.empty())
  {
    parse_errors = simulatorFrameErrors(config_.frames);
  }
  for (const std::string& e : parse_errors)
  {
    errors->push_back(pnh_.getNamespace() + "/" + e);
  }
  if (errors->size() != before)
  {
    return false;
  }
  std::string error;
  map_path_ = resolveResourcePath(config_.map_file, &error);
  if (map_path_.empty())
  {
    errors->push_back(pnh_.getNamespace() + "/map_file: " + error);
    return false;
  }
  try
  {
    map_ = std::make_shared<core::MapRayCaster>(io::loadMapFile(map_path_));  // .poly or .yaml
  }
  catch (const std::exception& e)
  {
    errors->push_back(pnh_.getNamespace() + "/map_file: " + e.what());
    return false;
  }
  std::vector<std::string> sim_errors;
  sim_ = core::Simulation::create(config_, map_, &sim_errors);
  for (const std::string& e : sim_errors)
  {
    errors->push_back(pnh_.getNamespace() + "/" + e);
  }
  return sim_ != nullptr;
}

void SimulatorNode::start()
{
  range_pub_ = nh_.advertise<sensor_msgs::Range>("range", 100);
  truth_pub_ = nh_.advertise<ReadingTruth>("ground_truth_readings", 100);
  if (config_.scan.enabled)
  {
    scan_pub_ = nh_.advertise<sensor_msgs::LaserScan>("scan", 10);
  }
  odom_pub_ = nh_.advertise<nav_msgs::Odometry>("odom", 100);
  ground_truth_pub_ = nh_.advertise<nav_msgs::Odometry>("ground_truth", 100);
  if (config_.publish_clock)
  {
    clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 100);
  }
  if (config_.visualization.markers)
  {
    map_markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("map_markers", 1, true);
    obstacle_markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("obstacle_markers", 10);
    ray_markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("ray_markers", 10);
  }
  if (config_.visualization.occupancy_grid)
  {
    grid_pub_ = nh_.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
  }
  if (config_.robot.motion == core::RobotMotion::CmdVel)
  {
    cmd_vel_sub_ = nh_.subscribe("cmd_vel", 10, &SimulatorNode::onCmdVel, this);
  }
  kidnap_srv_ = pnh_.advertiseService("kidnap", &SimulatorNode::onKidnap, this);
  reset_srv_ = pnh_.advertiseService("reset", &SimulatorNode::onReset, this);

  wall_start_ = ros::WallTime::now();
  base_stamp_ = config_.publish_clock ? ros::Time(wall_start_.sec, wall_start_.nsec) : ros::Time::now();
  if (config_.publish_clock)
  {
    rosgraph_msgs::Clock clock;
    clock.clock = base_stamp_;
    clock_pub_.publish(clock);
  }
  last_readings_.assign(config_.sensors.size(), core::SimReading());
  publishStaticTransforms();
  publishLatched();

  const double period = std::max(kMinTimerPeriod, sim_->stepSize() / config_.time_scale);
  timer_ = nh_.createWallTimer(ros::WallDuration(period), &SimulatorNode::onTimer, this);
  ROS_INFO("fdml_simulator: scenario '%s', map %s, %zu sensors, %zu obstacles, %s time x%.3g", config_.name.c_str(),
           map_path_.c_str(), config_.sensors.size(), sim_->scene().obstacles().size(),
           config_.publish_clock ? "simulated (/clock)" : "wall", config_.publish_clock ? config_.time_scale : 1.0);
}

ros::Time SimulatorNode::stampOf(double sim_time) const
{
  return base_stamp_ + ros::Duration(sim_time);
}

void SimulatorNode::onTimer(const ros::WallTimerEvent& /*event*/)
{
  const double scale = config_.publish_clock ? config_.time_scale : 1.0;
  const double target = (ros::WallTime::now() - wall_start_).toSec() * scale;
  for (int i = 0; i < kMaxStepsPerTick && sim_->time() + sim_->stepSize() <= target + 1e-9; ++i)
  {
    stepOnce();
  }
}

void SimulatorNode::stepOnce()
{
  sim_->step(&step_output_);
  const ros::Time stamp = stampOf(sim_->time());
  if (config_.publish_clock)
  {
    rosgraph_msgs::Clock clock;
    clock.clock = stamp;
    clock_pub_.publish(clock);
  }
  if (step_output_.odometry_due)
  {
    publishOdometry(stamp);
  }
  for (const core::SimReading& reading : step_output_.readings)
  {
    publishReading(reading, stamp);
  }
  if (step_output_.has_scan)
  {
    publishScan(step_output_.scan, stamp);
  }
  if (config_.visualization.markers && sim_->time() + 1e-9 >= next_marker_time_)
  {
    next_marker_time_ = sim_->time() + 1.0 / config_.visualization.marker_rate;
    publishMarkers(stamp);
  }
}

void SimulatorNode::publishOdometry(const ros::Time& stamp)
{
  const auto& f = config_.frames;
  odom_pub_.publish(
      odometryMsg(sim_->odomPose(), sim_->linearVelocity(), sim_->angularVelocity(), f.odom, f.base, stamp));
  ground_truth_pub_.publish(
      odometryMsg(sim_->truePose(), sim_->linearVelocity(), sim_->angularVelocity(), f.map, f.base, stamp));
  geometry_msgs::TransformStamped tf;
  tf.header.stamp = stamp;
  tf.header.frame_id = f.odom;
  tf.child_frame_id = f.base;
  tf.transform = toTransformMsg(sim_->odomPose());
  tf_broadcaster_.sendTransform(tf);
}

void SimulatorNode::publishReading(const core::SimReading& reading, const ros::Time& stamp)
{
  const core::SensorConfig& sensor = config_.sensors[static_cast<std::size_t>(reading.sensor)];
  last_readings_[static_cast<std::size_t>(reading.sensor)] = reading;
  ReadingTruth truth;
  truth.header.stamp = stamp;
  truth.header.frame_id = sensor.frame;
  truth.hit = hitCode(reading.kind);
  truth.obstacle_id = reading.obstacle;
  truth.range = reading.range;
  truth.true_range = reading.true_range;
  truth.map_range = reading.map_range;
  truth.sensor_pose = toPose2D(reading.sensor_pose);
  truth.dropped = reading.dropped;
  if (!reading.dropped)
  {
    sensor_msgs::Range range;
    range.header = truth.header;
    range.radiation_type = sensor_msgs::Range::INFRARED;
    range.field_of_view = static_cast<float>(sensor.fov);
    range.min_range = static_cast<float>(sensor.min_range);
    range.max_range = static_cast<float>(sensor.max_range);
    range.range = static_cast<float>(reading.range);
    range_pub_.publish(range);
  }
  truth_pub_.publish(truth);
}

void SimulatorNode::publishScan(const core::SimScan& scan, const ros::Time& stamp)
{
  const core::ScanConfig& sc = config_.scan;
  sensor_msgs::LaserScan msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = sc.frame;
  msg.angle_increment = static_cast<float>(core::kTwoPi / sc.beams);
  msg.angle_min = static_cast<float>(-core::kPi);
  msg.angle_max = static_cast<float>(-core::kPi + (sc.beams - 1) * core::kTwoPi / sc.beams);
  msg.time_increment = 0.0f;
  msg.scan_time = static_cast<float>(1.0 / sc.rate);
  msg.range_min = static_cast<float>(sc.min_range);
  msg.range_max = static_cast<float>(sc.max_range);
  msg.ranges.reserve(scan.ranges.size());
  for (double r : scan.ranges)
  {
    msg.ranges.push_back(static_cast<float>(r));
  }
  scan_pub_.publish(msg);
}

void SimulatorNode::publishMarkers(const ros::Time& stamp)
{
  const std::string& frame = config_.frames.map;
  visualization_msgs::MarkerArray obstacles = obstacleMarkers(sim_->scene().obstacles(), frame, stamp, marker_count_);
  marker_count_ = sim_->scene().obstacles().size();
  visualization_msgs::Marker robot;
  robot.header.frame_id = frame;
  robot.header.stamp = stamp;
  robot.ns = "robot";
  robot.type = visualization_msgs::Marker::ARROW;
  robot.action = visualization_msgs::Marker::ADD;
  robot.pose = toPoseMsg(sim_->truePose());
  robot.scale.x = 2.0 * config_.robot.radius;
  robot.scale.y = 0.5 * config_.robot.radius;
  robot.scale.z = 0.5 * config_.robot.radius;
  robot.color = makeColor(0.1f, 0.3f, 0.9f);
  obstacles.markers.push_back(robot);
  obstacle_markers_pub_.publish(obstacles);

  visualization_msgs::Marker rays;
  rays.header.frame_id = frame;
  rays.header.stamp = stamp;
  rays.ns = "rays";
  rays.type = visualization_msgs::Marker::LINE_LIST;
  rays.action = visualization_msgs::Marker::ADD;
  rays.pose.orientation.w = 1.0;
  rays.scale.x = 0.015;
  for (std::size_t i = 0; i < last_readings_.size(); ++i)
  {
    const core::SimReading& r = last_readings_[i];
    if (r.sensor < 0)
    {
      continue;
    }
    const double length = std::isfinite(r.true_range) ? r.true_range : config_.sensors[i].max_range;
    const std_msgs::ColorRGBA color = r.dropped                                ? makeColor(0.6f, 0.6f, 0.6f, 0.5f) :
                                      r.kind == core::SceneHit::Kind::Map      ? makeColor(0.1f, 0.8f, 0.2f) :
                                      r.kind == core::SceneHit::Kind::Obstacle ? makeColor(0.9f, 0.1f, 0.1f) :
                                                                                 makeColor(0.6f, 0.6f, 0.6f);
    rays.points.push_back(toPointMsg(r.sensor_pose.position(), 0.05));
    rays.points.push_back(toPointMsg(r.sensor_pose.position() + length * r.sensor_pose.heading(), 0.05));
    rays.colors.push_back(color);
    rays.colors.push_back(color);
  }
  visualization_msgs::MarkerArray ray_array;
  ray_array.markers.push_back(rays);
  ray_markers_pub_.publish(ray_array);
}

void SimulatorNode::publishStaticTransforms()
{
  std::vector<geometry_msgs::TransformStamped> transforms;
  auto add = [&](const std::string& frame, const core::Pose2& mount) {
    geometry_msgs::TransformStamped tf;
    tf.header.stamp = base_stamp_;
    tf.header.frame_id = config_.frames.base;
    tf.child_frame_id = frame;
    tf.transform = toTransformMsg(mount);
    transforms.push_back(tf);
  };
  for (const core::SensorConfig& s : config_.sensors)
  {
    add(s.frame, s.mount);
  }
  if (config_.scan.enabled)
  {
    add(config_.scan.frame, config_.scan.mount);
  }
  static_broadcaster_.sendTransform(transforms);
}

void SimulatorNode::publishLatched()
{
  if (config_.visualization.markers)
  {
    map_markers_pub_.publish(mapMarkers(map_->map(), config_.frames.map, base_stamp_));
  }
  if (config_.visualization.occupancy_grid)
  {
    // A floor plan (core::rasterize): walls a cell thick, obstacles solid, unknown outside.
    core::RasterizeOptions raster;
    raster.resolution = config_.visualization.grid_resolution;
    raster.margin = 2.0 * raster.resolution;
    raster.wall_thickness = raster.resolution;
    raster.fill_obstacles = true;
    grid_pub_.publish(toOccupancyGridMsg(core::rasterize(map_->map(), raster), config_.frames.map, base_stamp_));
  }
}

void SimulatorNode::onCmdVel(const geometry_msgs::Twist::ConstPtr& msg)
{
  sim_->setVelocityCommand(msg->linear.x, msg->angular.z);
}

bool SimulatorNode::onKidnap(Kidnap::Request& request, Kidnap::Response& response)
{
  core::Pose2 pose = fromPose2D(request.pose);
  response.success =
      request.random ? sim_->kidnapRandom(&pose, &response.message) : sim_->kidnap(pose, &response.message);
  response.pose = toPose2D(sim_->truePose());
  if (response.success)
  {
    ROS_INFO("fdml_simulator: %s", response.message.c_str());
  }
  else
  {
    ROS_WARN("fdml_simulator: kidnap refused: %s", response.message.c_str());
  }
  return true;
}

bool SimulatorNode::onReset(std_srvs::Empty::Request& /*request*/, std_srvs::Empty::Response& /*response*/)
{
  sim_->reset();
  ROS_INFO("fdml_simulator: reset to the initial state");
  return true;
}

}  // namespace fdml_localization
