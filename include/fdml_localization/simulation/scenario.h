/**
 * @file scenario.h
 * @brief The simulator's scenario: robot, sensors, odometry, dynamic obstacles and node
 *        options, parsed and validated from a configuration tree (a YAML file or the node's
 *        private ROS parameters). Units: [m], [rad], [s], [Hz].
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"
#include "fdml_localization/core/util/param_tree.h"

#include <cstdint>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// How the simulated robot moves.
enum class RobotMotion
{
  Rotate,     ///< in place at a constant angular speed (the paper's protocol)
  Waypoints,  ///< a closed loop of waypoints: turn towards the next one, then drive
  CmdVel      ///< follows velocity commands (geometry_msgs/Twist in the node)
};

/// How a dynamic obstacle moves.
enum class ObstacleMotion
{
  Static,     ///< never moves
  Bounce,     ///< constant velocity, reflected by walls and the robot
  Waypoints,  ///< a closed loop of waypoints at constant speed, waits while the robot blocks it
  RandomWalk  ///< constant speed, heading diffuses randomly, reflected like Bounce
};

/// Names of the map, odometry and base frames.
struct FramesConfig
{
  std::string map = "map";
  std::string odom = "odom";
  std::string base = "base_link";
};

/// The robot: a disc that never overlaps walls or obstacles.
struct RobotConfig
{
  double radius = 0.15;      ///< footprint radius [m], in (0, 5]
  bool random_start = true;  ///< start at a random free pose (seeded) when no start is given
  Pose2 start;               ///< start pose in the map [m, rad] (when !random_start)
  RobotMotion motion = RobotMotion::Rotate;
  double angular_speed = 0.5;      ///< rotate: turn rate; waypoints: turning speed [rad/s]
  double linear_speed = 0.3;       ///< waypoints: driving speed [m/s]
  std::vector<Vec2> waypoints;     ///< waypoints loop [m] (at least 2 for Waypoints)
  double cmd_vel_timeout = 0.5;    ///< cmd_vel: a command expires after this [s]
  double max_linear_speed = 1.0;   ///< cmd_vel: commands are clamped to this [m/s]
  double max_angular_speed = 3.0;  ///< cmd_vel: commands are clamped to this [rad/s]
};

/// One range sensor mounted on the base.
struct SensorConfig
{
  std::string frame;         ///< tf frame of the sensor (required, unique)
  Pose2 mount;               ///< pose on the base [m, rad]
  double rate = 10.0;        ///< readings per second [Hz]
  double min_range = 0.02;   ///< [m]
  double max_range = 4.0;    ///< [m]
  double fov = 0.05;         ///< field of view [rad] in [0, pi]: reads the nearest point in the cone; 0 = a ray
  double noise_sigma = 0.0;  ///< Gaussian range noise standard deviation [m]
  double dropout = 0.0;      ///< probability that a reading is lost, in [0, 1]
};

/// An optional sparse laser scan (N beams evenly over a full turn).
struct ScanConfig
{
  bool enabled = false;
  std::string frame = "base_scan";
  Pose2 mount;
  int beams = 10;
  double rate = 5.0;         ///< [Hz]
  double min_range = 0.02;   ///< [m]
  double max_range = 8.0;    ///< [m]
  double noise_sigma = 0.0;  ///< [m]
};

/// Odometry publication and drift.
struct OdometryConfig
{
  double rate = 0.0;               ///< odometry, tf and ground truth rate [Hz]; 0 = every step
  double translation_noise = 0.0;  ///< std of the position error after 1 m of travel [m]
  double rotation_noise = 0.0;     ///< std of the heading error after 1 rad of turning [rad]
};

/// A group of identical dynamic obstacles.
struct ObstacleGroupConfig
{
  int count = 1;
  bool polygon = false;  ///< shape: disc (false) or polygon (true)
  double radius = 0.1;   ///< disc radius [m]
  Ring vertices;         ///< polygon vertices relative to the obstacle's position [m]
  ObstacleMotion motion = ObstacleMotion::Static;
  double speed = 0.5;           ///< [m/s]
  double turn_sigma = 1.0;      ///< random walk: heading diffusion [rad/sqrt(s)]
  std::vector<Vec2> waypoints;  ///< waypoints motion: the loop [m]
  std::vector<Vec2> positions;  ///< start positions [m] (else random; waypoints: spread on the loop)
  std::uint64_t seed = 0;       ///< 0 = derived from the scenario seed and the group index
};

/// Visualization outputs.
struct VisualizationConfig
{
  bool markers = true;            ///< map, obstacle and ray markers
  double marker_rate = 10.0;      ///< obstacle and ray markers [Hz]
  bool occupancy_grid = false;    ///< publish nav_msgs/OccupancyGrid on `map`
  double grid_resolution = 0.05;  ///< [m]
};

/// Everything the simulator node reads from its private parameters.
struct ScenarioConfig
{
  std::string name;            ///< free text
  std::string map_file;        ///< .poly path or package://pkg/path (required)
  std::uint64_t seed = 1;      ///< seeds every random choice
  double step_rate = 100.0;    ///< simulation steps per simulated second [Hz]
  bool publish_clock = false;  ///< publish /clock and run at time_scale x real time
  double time_scale = 1.0;     ///< simulated seconds per wall second (with publish_clock)
  double clearance = 0.01;     ///< minimum gap kept between bodies and walls [m]
  FramesConfig frames;
  RobotConfig robot;
  std::vector<SensorConfig> sensors;
  ScanConfig scan;
  OdometryConfig odometry;
  std::vector<ObstacleGroupConfig> obstacles;
  VisualizationConfig visualization;
};

const char* toString(RobotMotion motion);
const char* toString(ObstacleMotion motion);

/**
 * @brief Parses and validates a scenario tree (its root is a map of the keys above).
 * @param root the tree
 * @param[out] config filled with every valid value (defaults elsewhere)
 * @return every problem found, each starting with the key path ("sensors[1].frame: ..."),
 *         including unknown keys; empty when the scenario is valid. Checks that need the map
 *         (obstacles that do not fit, waypoints in walls) are done by Simulation::create().
 */
std::vector<std::string> parseScenario(const ParamValue& root, ScenarioConfig* config);

}  // namespace core
}  // namespace fdml_localization
