/**
 * @file simulator_node.h
 * @brief The fdml_simulator node: wraps core::Simulation with ROS topics, tf, services and
 *        (optionally) a /clock running faster than real time.
 *
 * Publishes (relative to the node's namespace): `range` (sensor_msgs/Range),
 * `ground_truth_readings` (fdml_localization/ReadingTruth, one per reading, dropped ones too),
 * `scan` (sensor_msgs/LaserScan, optional), `odom` (nav_msgs/Odometry) and tf odom -> base,
 * `ground_truth` (nav_msgs/Odometry in the map frame), static tf base -> sensor frames,
 * `map_markers` (latched), `obstacle_markers`, `ray_markers` (visualization_msgs/MarkerArray),
 * `map` (nav_msgs/OccupancyGrid, latched, optional), `/clock` (with ~publish_clock).
 * Subscribes `cmd_vel` (geometry_msgs/Twist) in cmd_vel motion. Services `~kidnap`
 * (fdml_localization/Kidnap) and `~reset` (std_srvs/Empty).
 */
#pragma once

#include "fdml_localization/Kidnap.h"
#include "fdml_localization/simulation/simulation.h"

#include <geometry_msgs/Twist.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <memory>
#include <string>
#include <vector>

namespace fdml_localization
{
/**
 * @brief What is wrong with the simulator's frames, each message naming both parameters
 *        (frames.odom and frames.base, frames.map and frames.base): the odometry and map frames
 *        must differ from the base frame (tf cannot make a frame its own parent). Empty when usable.
 */
std::vector<std::string> simulatorFrameErrors(const core::FramesConfig& frames);

class SimulatorNode
{
public:
  /**
   * @param nh node handle for topics
   * @param pnh private node handle: the scenario parameters (see core/scenario.h) and services
   */
  SimulatorNode(const ros::NodeHandle& nh, const ros::NodeHandle& pnh);

  /**
   * @brief Reads and validates the private parameters, loads the map, builds the simulation,
   *        advertises everything and starts the wall-clock step timer.
   * @param errors every problem found, each naming its parameter
   * @return false (nothing started) when @p errors is non-empty
   */
  bool init(std::vector<std::string>* errors);

  /// The simulation (for introspection).
  const core::Simulation& simulation() const
  {
    return *sim_;
  }

private:
  /// Parses the scenario, loads the map and builds the simulation (init()'s first half).
  bool loadScenario(std::vector<std::string>* errors);
  /// Advertises the topics and services, publishes the static data and starts the timer.
  void start();
  void onTimer(const ros::WallTimerEvent& event);
  void stepOnce();
  ros::Time stampOf(double sim_time) const;

  void publishOdometry(const ros::Time& stamp);
  void publishReading(const core::SimReading& reading, const ros::Time& stamp);
  void publishScan(const core::SimScan& scan, const ros::Time& stamp);
  void publishMarkers(const ros::Time& stamp);
  void publishStaticTransforms();
  void publishLatched();

  void onCmdVel(const geometry_msgs::Twist::ConstPtr& msg);
  bool onKidnap(Kidnap::Request& request, Kidnap::Response& response);
  bool onReset(std_srvs::Empty::Request& request, std_srvs::Empty::Response& response);

  ros::NodeHandle nh_;
  ros::NodeHandle pnh_;
  core::ScenarioConfig config_;
  std::string map_path_;
  std::shared_ptr<const core::MapRayCaster> map_;
  std::unique_ptr<core::Simulation> sim_;

  ros::Publisher range_pub_;
  ros::Publisher truth_pub_;
  ros::Publisher scan_pub_;
  ros::Publisher odom_pub_;
  ros::Publisher ground_truth_pub_;
  ros::Publisher clock_pub_;
  ros::Publisher map_markers_pub_;
  ros::Publisher obstacle_markers_pub_;
  ros::Publisher ray_markers_pub_;
  ros::Publisher grid_pub_;
  ros::Subscriber cmd_vel_sub_;
  ros::ServiceServer kidnap_srv_;
  ros::ServiceServer reset_srv_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  ros::WallTimer timer_;

  ros::Time base_stamp_;      ///< stamp of simulated time 0
  ros::WallTime wall_start_;  ///< wall time of simulated time 0
  double next_marker_time_ = 0.0;
  std::vector<core::SimReading> last_readings_;  ///< per sensor, for the ray markers
  std::size_t marker_count_ = 0;
  core::StepOutput step_output_;
};

}  // namespace fdml_localization
