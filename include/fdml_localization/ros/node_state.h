/**
 * @file node_state.h
 * @brief What the localizer node's threads share: the one mutex, what it guards (the reading
 *        buffer, the job queue, the service waiters, the relocalization request, the pose hint,
 *        the tracking status and the counters), and the jobs the worker solves.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/ros/reading_buffer.h"

#include <fdml_localization/LocalizationResult.h>
#include <fdml_localization/Status.h>

#include <Eigen/Core>

#include <nav_msgs/OccupancyGrid.h>

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace fdml_localization
{
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
  std::uint64_t generation = 0;  ///< NodeState::generation when the batch was formed
  std::vector<OutcomePromise> waiters;
};

/// Counters and last outcomes shown by diagnostics.
struct NodeStatistics
{
  std::uint64_t batches_solved = 0;
  std::uint64_t batches_dropped = 0;  ///< dropped unsolved, oldest first, while kMaxQueuedBatches waited
  std::uint64_t solve_errors = 0;
  double last_solve_time = 0.0;  ///< [s]
  int last_candidates = -1;      ///< -1: nothing solved yet
  bool last_unambiguous = false;
  std::string last_error;
  std::uint64_t maps_received = 0;  ///< map messages received
  std::uint64_t maps_accepted = 0;  ///< map messages converted and in use
  std::uint64_t maps_rejected = 0;  ///< map messages that could not be used
  std::uint64_t maps_replaced = 0;  ///< map messages replaced by a newer one before conversion
  std::string last_map_error;
};

/// A user's pose hint (initialpose), applied by the worker to the next batch.
struct PoseHint
{
  core::Pose2 pose;                                      ///< the base in the map [m, rad]
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of (x, y, yaw)
};

/// The tracking status the worker reports (~status and diagnostics).
struct TrackingStatus
{
  std::uint8_t state = fdml_localization::Status::LOST;
  std::string message = "no hypothesis yet";
  int hypotheses = 0;
  double best_support = 0.0;
  double second_support = 0.0;
  std::uint64_t received_at_update = 0;  ///< ReadingBuffer::received() at the last update
  std::uint64_t kidnaps_detected = 0;
  std::uint64_t global_searches = 0;
};

/**
 * @brief The state the node's threads share. `mutex` guards every field: the sensor callbacks
 *        and the processing timer (SensorInput), the services (LocalizerNode), the worker
 *        (SolverWorker), the tf timer (ResultPublisher) and diagnostics read or write them
 *        only while holding it, and never hold it while solving, publishing or waiting.
 */
struct NodeState
{
  explicit NodeState(const ReadingBuffer::Options& buffer_options) : buffer(buffer_options)
  {}

  std::mutex mutex;                                ///< guards everything below
  std::condition_variable work_ready;              ///< signalled when a job or a map is queued, or on shutdown
  ReadingBuffer buffer;                            ///< readings waiting for tf and for a batch
  std::deque<Job> queued_batches;                  ///< sensor batches not yet taken by the worker, FIFO
  std::deque<Job> queued_requests;                 ///< ~localize requests, FIFO
  std::vector<OutcomePromise> relocalize_waiters;  ///< answered once a hypothesis is clearly supported
  bool shutting_down = false;
  std::uint64_t generation = 0;  ///< bumped by every relocalization request
  bool have_map_to_odom = false;
  core::Pose2 map_to_odom;                        ///< last unambiguous map -> odom
  nav_msgs::OccupancyGrid::ConstPtr pending_map;  ///< newest map message not yet taken by the worker
  bool have_map = false;                          ///< a map is in use (or will be, once the worker prepared it)
  std::string map_source;                         ///< where the map in use came from
  std::string activity = "starting";              ///< human-readable worker state
  NodeStatistics stats;
  /// A relocalization is under way (~relocalize, global_localization, start-up in continuous
  /// mode, a kidnap): global searches seed hypotheses until one is clearly supported.
  bool relocalizing = false;
  std::optional<PoseHint> pending_hint;  ///< the newest initialpose not yet applied
  TrackingStatus tracking;

  /// The ~status message now (caller holds mutex).
  fdml_localization::Status statusLocked() const;

  /// Sensor batches that may wait for the worker: each batch is one tracking update, and the
  /// tracker counts each fix as one of k / ~batch_stride overlapping batches, so every batch
  /// formed is solved; a worker that falls behind drops the oldest rather than lag (4 batches:
  /// 0.2 s at 20 batches a second, four sensors at 10 Hz with stride 2).
  static constexpr std::size_t kMaxQueuedBatches = 4;
  /// Queues a sensor batch for the worker, dropping the oldest beyond kMaxQueuedBatches (caller
  /// holds mutex).
  void queueBatchLocked(Job job);
  /// Answers every waiting service call with @p message (caller holds mutex).
  void failAllWaitersLocked(const std::string& message);
};

}  // namespace fdml_localization
