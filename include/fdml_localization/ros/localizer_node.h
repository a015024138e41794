/**
 * @file localizer_node.h
 * @brief The fdml_localizer node: a thin ROS wrapper composed of SensorInput (callbacks, tf,
 *        batches), SolverWorker (owns the core::Localizer), ResultPublisher and the diagnostics,
 *        sharing one NodeState (one mutex). The node itself holds the services.
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
 * Tracking (docs/localizer_node.md#tracking): the worker updates a core::HypothesisTracker with
 * every batch; global searches seed it at start (continuous mode), on ~relocalize,
 * global_localization and initialpose hints, on a detected kidnap (continuous mode) and after
 * ~global_interval updates without a clearly supported hypothesis (beside the tracking, in a
 * thread of their own: they never hold it). ~relocalize answers once one
 * hypothesis is clearly supported. ~pose and map -> odom follow every update while one is, and
 * are withdrawn otherwise; ~status reports the state.
 */
#pragma once

#include "fdml_localization/ros/map_loading.h"
#include "fdml_localization/ros/node_state.h"
#include "fdml_localization/ros/params.h"
#include "fdml_localization/ros/result_publisher.h"
#include "fdml_localization/ros/sensor_input.h"
#include "fdml_localization/ros/solver_worker.h"

#include <fdml_localization/Localize.h>
#include <fdml_localization/Relocalize.h>

#include <diagnostic_updater/diagnostic_updater.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include <memory>
#include <string>

namespace fdml_localization
{
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
  /// Fails waiting service calls, stops the timers and the spinner and joins the worker.
  ~LocalizerNode();

  LocalizerNode(const LocalizerNode&) = delete;
  LocalizerNode& operator=(const LocalizerNode&) = delete;

private:
  bool relocalizeService(fdml_localization::Relocalize::Request& req, fdml_localization::Relocalize::Response& res);
  bool localizeService(fdml_localization::Localize::Request& req, fdml_localization::Localize::Response& res);
  bool globalLocalizationService(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  /// Clears the buffer and arms the next batch of fresh readings (caller holds the mutex).
  void startRelocalizationLocked(const OutcomePromise& waiter);
  /// The message of a service refused before the worker can answer; empty when it can.
  std::string refusalLocked() const;
  void mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& msg);
  /// Stores a user's pose hint for the worker (ignores this node's own hand-over).
  void initialPoseCallback(const ros::MessageEvent<const geometry_msgs::PoseWithCovarianceStamped>& event);
  void processTimer(const ros::WallTimerEvent& event);
  void statusTimer(const ros::WallTimerEvent& event);
  void tfTimer(const ros::WallTimerEvent& event);

  Params params_;
  ros::NodeHandle nh_;
  ros::NodeHandle private_nh_;
  ros::NodeHandle service_nh_;         ///< private namespace on service_queue_
  ros::NodeHandle global_service_nh_;  ///< node namespace on service_queue_
  ros::CallbackQueue service_queue_;
  std::unique_ptr<ros::AsyncSpinner> service_spinner_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  diagnostic_updater::Updater diagnostics_;

  NodeState state_;  ///< shared with the parts below; its mutex guards it
  ResultPublisher publisher_;
  SensorInput input_;
  ros::Subscriber map_sub_;  ///< with ~use_map_topic only
  ros::Subscriber initialpose_sub_;
  std::unique_ptr<SolverWorker> worker_;
  ros::ServiceServer relocalize_srv_;
  ros::ServiceServer localize_srv_;
  ros::ServiceServer global_localization_srv_;
  ros::WallTimer process_timer_;
  ros::WallTimer status_timer_;
  ros::WallTimer tf_timer_;
};

/**
 * @brief The fdml_localizer node's life: loads and validates the parameters (logging every
 *        error), loads the map, runs the node until shutdown.
 * @return the process exit status: 0, 2 for invalid parameters, 1 when the map cannot be loaded
 */
int runLocalizerNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);

}  // namespace fdml_localization
