/**
 * @file solver_worker.h
 * @brief The localizer node's worker thread: owns the core::Localizer and the
 *        core::HypothesisTracker, takes jobs (~localize requests first, then the newest sensor
 *        batch) and new maps from the shared state. A sensor batch updates the tracker (a global
 *        search seeds it when needed, see docs/localizer_node.md#tracking); the outcome goes to
 *        the publisher and the waiting service calls.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/tracking/hypothesis_tracker.h"
#include "fdml_localization/ros/map_loading.h"
#include "fdml_localization/ros/node_state.h"
#include "fdml_localization/ros/params.h"
#include "fdml_localization/ros/result_publisher.h"

#include <nav_msgs/OccupancyGrid.h>

#include <future>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

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
  /// Warns (once per node) when the distance-table cache could not be used (core::tableCacheWarning).
  void warnCacheOnce(core::Localizer& localizer);
  /// Takes the next map or job from the shared state; false on shutdown.
  bool takeWork(Job* job, nav_msgs::OccupancyGrid::ConstPtr* map);
  /// A ~localize request: one global solve of its readings.
  Outcome solve(const Job& job);
  /// ~result for @p result: in the map frame; for a sensor batch stamped at its newest reading,
  /// with the poses carried forward to it by odometry.
  fdml_localization::LocalizationResult resultMessage(const Job& job, const core::Result& result) const;
  /// The human-readable outcome of a solve.
  static std::string describeOutcome(const core::Result& result, bool unambiguous);
  /// The core options for @p map: the parameters, with grid tolerances for a converted grid.
  core::LocalizerOptions optionsFor(const LoadedMap& map) const;
  /// The adaptive engine within ~global_deadline, otherwise @p options.
  std::unique_ptr<core::Localizer> globalLocalizerFor(const std::shared_ptr<const core::MapRayCaster>& map,
                                                      core::LocalizerOptions options) const;
  /// Builds localizer_'s tables beside the worker (logs when ready).
  void prepareInBackground();
  /// Joins the table build started by prepareInBackground().
  void waitForTables();
  /// The tracker for @p map, with the localizer's tolerances.
  std::unique_ptr<core::HypothesisTracker> trackerFor(const std::shared_ptr<const core::MapRayCaster>& map,
                                                      const core::LocalizerOptions& options) const;
  /// Converts @p msg, builds and prepares its localizer and swaps both in; on failure logs and
  /// counts the reason and keeps the previous map.
  void applyMap(const nav_msgs::OccupancyGrid::ConstPtr& msg);

  // Tracking of sensor batches (solver_worker_tracking.cpp).
  /// What the shared state asks of the next sensor batch.
  struct Directive
  {
    bool stale = false;         ///< formed before the latest relocalization request
    bool restart = false;       ///< a relocalization request since the last batch: drop hypotheses
    bool relocalizing = false;  ///< a relocalization is under way
    std::optional<PoseHint> hint;
  };
  Directive takeDirective(const Job& job);
  /// A sensor batch: a hint, a global search or a tracking update, then publishing.
  Outcome trackBatch(const Job& job);
  /// A hint, a global search or a tracking update on @p job; the event to report (empty: none).
  std::string stepTracker(const Directive& directive, const Job& job);
  /// The event of a track lost since the last batch (sets @p kidnap), or empty.
  std::string lostTrackEvent(core::TrackState track, bool* kidnap);
  /// ~result, ~candidates, markers; ~pose, map -> odom and the hand-over while clearly supported.
  void publishTracking(const Job& job, const core::Result& result, const Outcome& outcome);
  /// Starts a global search on @p job's readings beside the tracking (global_search_).
  void startGlobalSearch(const Job& job);
  /// Seeds the tracker with the candidates of a finished global search, its new places carried
  /// through the batches the tracker remembered (those that came while it ran included); counts
  /// one more such batch while it runs. The event (empty: none finished, or it was for
  /// hypotheses dropped since by a relocalization request).
  std::string collectGlobalSearch();
  /// Applies a pose hint to the tracker; the outcome as text.
  std::string applyHint(const PoseHint& hint, const Job& job);
  /// The hypotheses as a core::Result (poses at the batch's first reading), best first.
  core::Result trackedResult(const Job& job) const;
  /// Records the outcome in the shared state (status, map -> odom, waiters to answer).
  /// @return the relocalization waiters to answer (when one hypothesis became clearly supported)
  std::vector<OutcomePromise> recordTracking(const Job& job, const std::string& event, bool kidnap, std::uint8_t state,
                                             Outcome* outcome);

  const Params& params_;
  NodeState& state_;
  ResultPublisher& publisher_;
  std::string map_topic_;
  std::shared_ptr<const core::MapRayCaster> map_;  ///< worker thread only; null until a map
  std::unique_ptr<core::Localizer> localizer_;     ///< worker thread only (~localize); null until a map
  /// The tracking global searches' localizer: the adaptive engine within ~global_deadline (no
  /// table to wait for); worker thread only, null until a map
  std::unique_ptr<core::Localizer> global_localizer_;
  /// Prepares localizer_ (the voxel engine's table) beside the tracking at start; joined before
  /// localizer_ is used or replaced (waitForTables())
  std::thread table_thread_;
  /// A global search under way beside the tracking (global_localizer_ is used by it alone).
  struct PendingSearch
  {
    std::future<core::Result> result;
    core::Pose2 reference;         ///< the odometry pose of the base its readings refer to
    std::uint64_t generation = 0;  ///< NodeState::generation it was started in
    std::size_t readings = 0;
    /// Batches the tracker remembered after its batch (at most core::kMaxCatchUp, about 5 s at an
    /// update every 0.05 s): its new places are carried through them (and those before).
    std::size_t since = 0;
  };
  std::optional<PendingSearch> global_search_;        ///< worker thread only
  std::unique_ptr<core::HypothesisTracker> tracker_;  ///< worker thread only; null until a map
  std::uint64_t generation_ = 0;                      ///< NodeState::generation of the last batch
  int updates_since_global_ = 0;                      ///< tracking updates since the last global search
  bool handover_pending_ = false;                     ///< ~publish_initialpose: a relocalization awaits its fix
  bool published_empty_ = false;                      ///< the last ~result published had no hypothesis
  bool was_tracking_ = false;                         ///< the last batch had a clearly supported hypothesis
  std::thread thread_;
  bool cache_warned_ = false;  ///< worker thread, or the table build while it runs
};

}  // namespace fdml_localization
