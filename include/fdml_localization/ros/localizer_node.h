/**
 * @file localizer_node.h
 * @brief The fdml_localizer node: a thin ROS wrapper that owns a core::Localizer.
 *
 * Threads:
 * - the caller's spinner (ros::spin() in main) runs the sensor callbacks and the wall timers;
 *   callbacks only check and buffer readings, the timer resolves their tf (without waiting),
 *   forms batches, republishes map -> odom and updates diagnostics;
 * - an AsyncSpinner on a private callback queue runs the services, so a ~relocalize call that
 *   waits for readings never stalls the sensor callbacks;
 * - one worker thread owns the core::Localizer and solves: queued ~localize requests first, then
 *   the newest sensor batch (a newer batch replaces one still queued).
 *
 * Maps: ~map_file (a .poly or a map_server .yaml, loaded before the node starts) and, with
 * ~use_map_topic, nav_msgs/OccupancyGrid messages on `map` (as AMCL takes them). The map callback
 * only stores the newest message; the worker converts it, builds a new core::Localizer (its
 * tables) and swaps it in between two solves, so a new map takes effect atomically for the next
 * solve. A grid that cannot be converted is logged and counted and the previous map stays in
 * use. Until there is a map, ~relocalize and ~localize fail with "no map yet".
 *
 * Relocalization (~relocalize, global_localization) clears the buffer and waits for k fresh
 * readings, each taken at its own stamp: the readings must differ, so the robot must rotate
 * in place (or drive) or the sensors must sweep while it waits. The readings' relative poses
 * come from odometry and the sensors' mounting on tf. map -> odom is not published from the
 * request until the next unambiguous answer.
 *
 * ~pose and map -> odom are published only when the best candidate is unambiguous: there is
 * exactly one candidate, or the best explains strictly more readings than the second
 * (the core ranks by inliers, then rms). Candidates tied on inliers are different places
 * that explain the readings equally well (e.g. a symmetric room): no pose is claimed.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/ros/map_loading.h"
#include "fdml_localization/ros/params.h"
#include "fdml_localization/ros/reading_buffer.h"

#include <fdml_localization/LocalizationResult.h>
#include <fdml_localization/Localize.h>
#include <fdml_localization/Relocalize.h>

#include <diagnostic_updater/diagnostic_updater.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <condition_variable>
#include <deque>
#include <future>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace fdml_localization
{
/// Whether the best of a result is unambiguous (see the file comment for the rule).
bool isUnambiguous(const core::Result& result);

/// Pose of the base at the newest reading: @p pose (the base at t_1 in the map) carried forward
/// by the odometry between @p base_first and @p base_newest (both in odom).
core::Pose2 carryForward(const core::Pose2& pose, const core::Pose2& base_first, const core::Pose2& base_newest);

/// The covariance of carryForward()'s result from the covariance of @p pose (first order).
Eigen::Matrix3d carryForwardCovariance(const Eigen::Matrix3d& covariance, const core::Pose2& pose,
                                       const core::Pose2& base_first, const core::Pose2& base_newest);

class LocalizerNode
{
public:
  /**
   * @param nh namespace of the input topics and of global_localization
   * @param private_nh namespace of the outputs, ~relocalize and ~localize
   * @param params validated parameters
   * @param map the map loaded from ~map_file; its map may be null with ~use_map_topic (the node
   *        then waits for one on the map topic)
   * @throws std::invalid_argument when the core rejects the options
   */
  LocalizerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const Params& params,
                const LoadedMap& map);
  /// Fails waiting service calls, stops the spinners and joins the worker.
  ~LocalizerNode();

  LocalizerNode(const LocalizerNode&) = delete;
  LocalizerNode& operator=(const LocalizerNode&) = delete;

private:
  /// What a service caller waits for.
  struct Outcome
  {
    bool success = false;
    std::string message;
    fdml_localization::LocalizationResult result;
  };
  using OutcomePromise = std::shared_ptr<std::promise<Outcome>>;

  /// One solve for the worker.
  struct Job
  {
    std::vector<core::Reading> readings;
    bool from_sensors = false;     ///< true: a tf batch (published); false: a ~localize request
    Batch batch;                   ///< from_sensors only
    std::uint64_t generation = 0;  ///< relocalization_generation_ when the batch was formed
    std::vector<OutcomePromise> waiters;
  };

  // Inputs (localizer_node.cpp).
  void rangeCallback(const sensor_msgs::Range::ConstPtr& msg);
  void scanCallback(const sensor_msgs::LaserScan::ConstPtr& msg);
  void processTimer(const ros::WallTimerEvent& event);
  LookupStatus lookupInOdom(const std::string& frame, std::int64_t stamp, core::Pose2* pose) const;
  void warnDropped(const std::string& frame, const std::string& reason);

  // Services (localizer_node.cpp).
  bool relocalizeService(fdml_localization::Relocalize::Request& req, fdml_localization::Relocalize::Response& res);
  bool localizeService(fdml_localization::Localize::Request& req, fdml_localization::Localize::Response& res);
  bool globalLocalizationService(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  /// Clears the buffer and arms the next batch of fresh readings (caller holds mutex_).
  void startRelocalizationLocked(const OutcomePromise& waiter);

  // Worker (localizer_node.cpp).
  void workerLoop();
  Outcome solve(const Job& job);

  // Maps (localizer_node_map.cpp).
  /// Constructor step: the localizer of the ~map_file map (if any), the map topic subscription.
  void setUpMaps(const LoadedMap& map);
  void mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& msg);
  /// The core options for @p map: the parameters, with withGridTolerances() for a converted grid
  /// (the effective tolerances are logged).
  core::LocalizerOptions optionsFor(const LoadedMap& map) const;
  /// Worker: converts @p msg, builds and prepares its localizer, and swaps both in; on failure
  /// logs and counts the reason and keeps the previous map.
  void applyMap(const nav_msgs::OccupancyGrid::ConstPtr& msg);
  /// The answer of a request made before any map arrived.
  std::string noMapMessage() const;

  // Outputs (localizer_node_publish.cpp).
  void publishBatchOutcome(const Job& job, const core::Result& result, const Outcome& outcome);
  void publishMapToOdom(const ros::WallTimerEvent& event);
  void publishMapMarkers();
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  Params params_;
  SolveMode mode_;
  std::shared_ptr<const core::MapRayCaster> map_;  ///< null until a map; swapped by the worker only
  std::unique_ptr<core::Localizer> localizer_;     ///< used by the worker thread only; null until a map

  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  ros::NodeHandle service_nh_;         ///< private namespace on service_queue_
  ros::NodeHandle global_service_nh_;  ///< node namespace on service_queue_
  ros::CallbackQueue service_queue_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;

  ros::Subscriber range_sub_;
  ros::Subscriber scan_sub_;
  ros::Subscriber map_sub_;  ///< with ~use_map_topic only
  ros::Publisher candidates_pub_;
  ros::Publisher result_pub_;
  ros::Publisher pose_pub_;
  ros::Publisher map_markers_pub_;
  ros::Publisher reading_markers_pub_;
  ros::ServiceServer relocalize_srv_;
  ros::ServiceServer localize_srv_;
  ros::ServiceServer global_localization_srv_;
  ros::WallTimer process_timer_;
  ros::WallTimer tf_timer_;
  diagnostic_updater::Updater diagnostics_;

  /// Guards every field below (the buffer, the job queue, the shared state the worker,
  /// the callbacks, the timers, the services and diagnostics read or write). Never held
  /// while solving, publishing or waiting.
  std::mutex mutex_;
  std::condition_variable work_ready_;  ///< signalled when a job is queued or on shutdown
  ReadingBuffer buffer_;
  std::unique_ptr<Job> queued_batch_;               ///< newest sensor batch not yet taken by the worker
  std::deque<Job> queued_requests_;                 ///< ~localize requests, FIFO
  std::vector<OutcomePromise> relocalize_waiters_;  ///< for the next sensor batch
  bool shutting_down_ = false;
  std::uint64_t relocalization_generation_ = 0;  ///< bumped by every relocalization request
  bool have_map_to_odom_ = false;
  core::Pose2 map_to_odom_;  ///< last unambiguous map -> odom
  std::uint64_t batches_solved_ = 0;
  std::uint64_t batches_replaced_ = 0;
  std::uint64_t solve_errors_ = 0;
  double last_solve_time_ = 0.0;  ///< [s]
  int last_candidates_ = -1;      ///< -1: nothing solved yet
  bool last_unambiguous_ = false;
  std::string last_error_;
  std::string state_ = "starting";                 ///< human-readable worker state
  nav_msgs::OccupancyGrid::ConstPtr pending_map_;  ///< newest map message not yet taken by the worker
  bool have_map_ = false;                          ///< a map is in use (or will be, once the worker prepared it)
  std::string map_source_;                         ///< where the map in use came from
  std::uint64_t maps_received_ = 0;                ///< map messages received
  std::uint64_t maps_accepted_ = 0;                ///< map messages converted and in use
  std::uint64_t maps_rejected_ = 0;                ///< map messages that could not be used
  std::uint64_t maps_replaced_ = 0;                ///< map messages replaced by a newer one before conversion
  std::string last_map_error_;

  std::thread worker_;  ///< started last, joined in the destructor
};

/**
 * @brief The fdml_localizer node's life: loads and validates the parameters (logging every
 *        error), loads the map, runs the node until shutdown.
 * @return the process exit status: 0, 2 for invalid parameters, 1 when the map cannot be loaded
 */
int runLocalizerNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);

}  // namespace fdml_localization
