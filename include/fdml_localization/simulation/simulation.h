/**
 * @file simulation.h
 * @brief ROS-free simulation of a disc robot with range sensors among dynamic obstacles in a
 *        polygon map: robot motion, obstacle motion, odometry drift, sensor noise and dropout,
 *        kidnapping. Deterministic for a given scenario seed (std::mt19937_64).
 *        Units: [m], [rad], [s].
 */
#pragma once

#include "fdml_localization/simulation/scenario.h"
#include "fdml_localization/simulation/scene.h"

#include <memory>
#include <random>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// One simulated range reading.
struct SimReading
{
  int sensor = -1;                             ///< index into ScenarioConfig::sensors
  double time = 0.0;                           ///< simulated time of the reading [s]
  Pose2 sensor_pose;                           ///< ground-truth sensor pose in the map
  SceneHit::Kind kind = SceneHit::Kind::None;  ///< what the ray hit first
  int obstacle = -1;                           ///< obstacle index when kind == Obstacle
  double range = kInf;       ///< published range [m]: noisy; +inf no return, -inf closer than min_range
  double true_range = kInf;  ///< noise-free range to the first hit [m] (+inf beyond max_range)
  double map_range = kInf;   ///< noise-free range to the static map [m] (+inf beyond max_range)
  bool dropped = false;      ///< lost by dropout (not published as a Range)
};

/// One simulated sparse scan.
struct SimScan
{
  double time = 0.0;                  ///< [s]
  Pose2 sensor_pose;                  ///< scan frame pose in the map
  std::vector<double> ranges;         ///< per beam [m], +inf no return; beam i at -pi + i 2pi/N
  std::vector<SceneHit::Kind> kinds;  ///< per beam: what it hit
};

/// What happened during one step.
struct StepOutput
{
  std::vector<SimReading> readings;
  bool has_scan = false;
  SimScan scan;
  bool odometry_due = false;  ///< odometry, tf and ground truth should be published now
};

/// The state of one dynamic obstacle (its shape is fixed; it only translates).
struct ObstacleState
{
  int group = 0;
  Vec2 position = Vec2::Zero();   ///< disc centre / polygon reference point [m]
  Vec2 velocity = Vec2::Zero();   ///< [m/s]
  std::size_t next_waypoint = 0;  ///< waypoints motion: index of the target waypoint
  int direction = 1;              ///< waypoints motion: +1 along the loop, -1 backwards
  double blocked_time = 0.0;      ///< waypoints motion: how long it has waited for the robot [s]
};

class Simulation
{
public:
  /**
   * @brief Builds the simulation: places the robot (given or random start), then every
   *        obstacle (given or random positions), and checks waypoints against the map.
   * @param errors receives every problem, naming the key (e.g. "obstacles[0].positions[2]: ...")
   * @return nullptr when @p errors is non-empty
   */
  static std::unique_ptr<Simulation> create(const ScenarioConfig& config, std::shared_ptr<const MapRayCaster> map,
                                            std::vector<std::string>* errors);

  /// Advances by one step of 1 / step_rate seconds and reports readings taken in it.
  void step(StepOutput* out);

  double time() const
  {
    return time_;
  }
  double stepSize() const
  {
    return dt_;
  }
  const ScenarioConfig& config() const
  {
    return config_;
  }
  const Scene& scene() const
  {
    return scene_;
  }
  const std::vector<ObstacleState>& obstacleStates() const
  {
    return obstacles_;
  }

  /// Ground-truth pose of the base in the map.
  const Pose2& truePose() const
  {
    return true_pose_;
  }
  /// Odometry pose of the base in the odom frame (identity at start and after reset()).
  const Pose2& odomPose() const
  {
    return odom_pose_;
  }
  /// Body-frame velocity of the base during the last step: forward [m/s] and turn rate [rad/s].
  double linearVelocity() const
  {
    return linear_velocity_;
  }
  double angularVelocity() const
  {
    return angular_velocity_;
  }

  /// cmd_vel motion: sets the command, clamped to the configured limits, valid for
  /// cmd_vel_timeout seconds of simulated time.
  void setVelocityCommand(double linear, double angular);

  /**
   * @brief Teleports the robot without telling odometry.
   * @return false (state unchanged) when the pose is not free for the robot; @p message says why.
   */
  bool kidnap(const Pose2& pose, std::string* message);
  /// Teleports to a random free pose; false when none was found.
  bool kidnapRandom(Pose2* pose, std::string* message);
  /// Restores the initial robot pose, obstacles and odometry (time keeps running).
  void reset();

  /// True when a robot disc at @p p is clear of walls (by the clearance) and of every obstacle.
  bool robotFits(const Vec2& p) const;
  /// True when obstacle @p index at @p position is clear of walls and of the robot disc at @p robot.
  bool obstacleFits(std::size_t index, const Vec2& position, const Vec2& robot) const;

  /// The obstacle's geometry at a position.
  Obstacle obstacleAt(std::size_t index, const Vec2& position) const;

private:
  Simulation(const ScenarioConfig& config, std::shared_ptr<const MapRayCaster> map);

  bool placeRobot(std::vector<std::string>* errors);
  bool placeObstacles(std::vector<std::string>* errors);
  bool placeObstacle(std::size_t group, int k, ObstacleState* state, std::string* error);
  bool obstacleApart(std::size_t index, const Vec2& p) const;
  bool checkWaypoints(std::vector<std::string>* errors) const;
  bool discClearOfWalls(const Vec2& centre, double radius) const;
  bool pathClearOfWalls(const Vec2& a, const Vec2& b, double radius) const;
  bool randomFreePose(Pose2* pose);

  void moveRobot();
  void moveObstacles();
  void moveObstacle(std::size_t index);
  void moveAlongWaypoints(std::size_t index);
  void moveOrReflect(std::size_t index);
  void updateOdometry(const Pose2& before);
  void syncScene();
  void takeReadings(StepOutput* out);
  SimReading readSensor(int index);
  double noisyRange(const SceneHit& hit, double min_range, double max_range, double sigma);

  ScenarioConfig config_;
  std::shared_ptr<const MapRayCaster> map_;
  Scene scene_;
  std::mt19937_64 rng_;                      ///< robot, sensors and odometry
  std::vector<std::mt19937_64> group_rngs_;  ///< per obstacle group: placement and motion
  double dt_ = 0.01;
  double time_ = 0.0;
  long steps_ = 0;

  Pose2 true_pose_;
  Pose2 odom_pose_;
  Pose2 initial_pose_;
  double linear_velocity_ = 0.0;
  double angular_velocity_ = 0.0;
  std::size_t robot_waypoint_ = 0;
  std::size_t initial_waypoint_ = 0;
  bool robot_waypoints_enabled_ = true;  ///< false after a kidnap left the loop unreachable
  double command_linear_ = 0.0;
  double command_angular_ = 0.0;
  double command_expiry_ = -1.0;

  std::vector<Ring> shapes_;   ///< per obstacle: polygon relative to its position
  std::vector<double> radii_;  ///< per obstacle: disc radius or bounding radius
  std::vector<ObstacleState> obstacles_;
  std::vector<ObstacleState> initial_obstacles_;

  std::vector<double> next_sensor_time_;
  double next_scan_time_ = 0.0;
  double next_odom_time_ = 0.0;
};

}  // namespace core
}  // namespace fdml_localization
