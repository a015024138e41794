/**
 * @file solver_worker.h
 * @brief The localizer node's worker thread: owns the core::Localizer, takes jobs (~localize
 *        requests first, then the newest sensor batch) and new maps from the shared state,
 *        solves, and hands the outcome to the publisher and the waiting service calls.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/ros/map_loading.h"
#include "fdml_localization/ros/node_state.h"
#include "fdml_localization/ros/params.h"
#include "fdml_localization/ros/result_publisher.h"

#include <nav_msgs/OccupancyGrid.h>

#include <memory>
#include <string>
#include <thread>

namespace fdml_localization
{
class SolverWorker
{
public:
  /**
   * @param map the map loaded from ~map_file (its map may be null with ~use_map_topic)
   * @param map_topic the resolved map topic, for messages
   * @throws std::invalid_argument when the core rejects the options
   */
  SolverWorker(const Params& params, NodeState& state, ResultPublisher& publisher, const LoadedMap& map,
               std::string map_topic);
  /// Joins the thread (the caller sets NodeState::shutting_down and notifies first).
  ~SolverWorker();

  /// Starts the thread: prepares the localizer's tables, then solves until shutdown.
  void start();

  /// The answer of a request made before any map arrived.
  std::string noMapMessage() const;

private:
  void loop();
  /// Takes the next map or job from the shared state; false on shutdown.
  bool takeWork(Job* job, nav_msgs::OccupancyGrid::ConstPtr* map);
  Outcome solve(const Job& job);
  /// ~result for @p result: in the map frame; for a sensor batch stamped at its newest reading,
  /// with the poses carried forward to it by odometry.
  fdml_localization::LocalizationResult resultMessage(const Job& job, const core::Result& result) const;
  /// The human-readable outcome of a solve.
  static std::string describeOutcome(const core::Result& result, bool unambiguous);
  /// Adds the drop counts to @p outcome and records a solved sensor batch in the shared state.
  /// @return true when the batch vouches for a new map -> odom (set in @p map_to_odom)
  bool recordBatch(const Job& job, const core::Result& result, bool solved, bool unambiguous, Outcome* outcome,
                   core::Pose2* map_to_odom);
  /// The core options for @p map: the parameters, with grid tolerances for a converted grid.
  core::LocalizerOptions optionsFor(const LoadedMap& map) const;
  /// Converts @p msg, builds and prepares its localizer and swaps both in; on failure logs and
  /// counts the reason and keeps the previous map.
  void applyMap(const nav_msgs::OccupancyGrid::ConstPtr& msg);

  const Params& params_;
  NodeState& state_;
  ResultPublisher& publisher_;
  std::string map_topic_;
  std::shared_ptr<const core::MapRayCaster> map_;  ///< worker thread only; null until a map
  std::unique_ptr<core::Localizer> localizer_;     ///< worker thread only; null until a map
  std::thread thread_;
};

}  // namespace fdml_localization
