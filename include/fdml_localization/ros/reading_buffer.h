/**
 * @file reading_buffer.h
 * @brief ROS-free batching of timestamped range readings for the localizer node: checks each
 *        reading, resolves its sensor and base poses through a lookup functor (tf in the node,
 *        a table in tests), forms batches of k readings with g_i = T(base at t_1)^-1 T(sensor at
 *        t_i), and counts every dropped reading by reason. Not thread-safe (the node guards it
 *        with its mutex).
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"

#include <cstdint>
#include <deque>
#include <functional>
#include <list>
#include <map>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace fdml_localization
{
/// Stable drop-reason identifiers (reported in LocalizationResult.drop_reasons and diagnostics).
namespace drop_reason
{
constexpr const char* kNanRange = "nan_range";                          ///< range is NaN
constexpr const char* kNegativeInfinity = "negative_infinity";          ///< -inf: too close (REP-117)
constexpr const char* kNegativeRange = "negative_range";                ///< finite range < 0
constexpr const char* kBelowMinRange = "below_min_range";               ///< range < min_range
constexpr const char* kAboveMaxRange = "above_max_range";               ///< finite range > max_range
constexpr const char* kInvalidLimits = "invalid_limits";                ///< min/max_range NaN, max <= 0 or max < min
constexpr const char* kInvalidFieldOfView = "invalid_field_of_view";    ///< Range.field_of_view NaN or outside [0, pi]
constexpr const char* kEmptyFrameId = "empty_frame_id";                 ///< header.frame_id is empty
constexpr const char* kZeroStamp = "zero_stamp";                        ///< header.stamp is 0 (unusable with odometry)
constexpr const char* kStampBackwards = "stamp_backwards";              ///< older than the last reading of its frame
constexpr const char* kFutureStamp = "future_stamp";                    ///< stamped beyond ~future_tolerance ahead
constexpr const char* kInvalidScan = "invalid_scan";                    ///< a LaserScan header fails its checks
constexpr const char* kUnknownFrame = "unknown_frame";                  ///< frame never appeared on tf in time
constexpr const char* kTransformUnavailable = "transform_unavailable";  ///< no tf at the stamp in time
constexpr const char* kBufferOverflow = "buffer_overflow";              ///< too many readings waiting for tf
}  // namespace drop_reason

/**
 * @brief The frame id as tf2 expects it: leading '/' removed (tf2 rejects such ids, with one
 *        warning per lookup; tf (1) accepted them, and tf2 strips them from incoming transforms).
 */
std::string tf2FrameId(const std::string& frame_id);

/// A reading as received, before its transforms are known.
struct TimedReading
{
  std::string frame_id;           ///< sensor frame (the Range/LaserScan header frame)
  std::int64_t stamp = 0;         ///< acquisition time [ns] (integer, so tf lookups hit stamps exactly)
  core::Pose2 beam;               ///< the beam's pose in the sensor frame (a LaserScan beam: (0, 0, angle))
  double range = core::kInf;      ///< [m]; +inf = no return
  double max_range = core::kInf;  ///< [m]
  double half_angle = 0.0;        ///< cone half-angle [rad]: Range.field_of_view / 2 (0 = a ray)
  double received = 0.0;          ///< arrival time on the node's clock [s] (starts the transform wait)
};

/// A reading with its poses in the odometry frame, both at the reading's own stamp.
struct ResolvedReading
{
  TimedReading raw;
  core::Pose2 sensor_in_odom;  ///< the beam's pose in odom [m, rad]
  core::Pose2 base_in_odom;    ///< the base's pose in odom [m, rad]
};

/// Outcome of a pose lookup.
enum class LookupStatus
{
  Ok,           ///< *pose is set
  NotYet,       ///< the frame is known but the transform at the stamp is not available (yet)
  UnknownFrame  ///< the frame is not (yet) known at all
};

/**
 * @brief Looks up the pose of @p frame in the odometry frame at @p stamp [ns].
 *        Must not block (the node passes a zero tf timeout).
 */
using PoseLookup = std::function<LookupStatus(const std::string& frame, std::int64_t stamp, core::Pose2* pose)>;

/// A batch ready for the solver.
struct Batch
{
  std::vector<core::Reading> readings;   ///< g_i relative to the base at the first reading
  std::vector<ResolvedReading> sources;  ///< the same readings, with their odom poses
  std::int64_t first_stamp = 0;          ///< t_1 [ns]
  std::int64_t newest_stamp = 0;         ///< the latest stamp in the batch [ns]
  core::Pose2 base_first;                ///< base in odom at t_1
  core::Pose2 base_newest;               ///< base in odom at newest_stamp
};

/// Batching and drop accounting. See the file comment.
class ReadingBuffer
{
public:
  struct Options
  {
    int batch_size = 10;               ///< k (>= 1)
    int stride = 1;                    ///< continuous mode: readings the window slides by, in [1, k]
    bool continuous = false;           ///< false: one batch per request (see requestBatch())
    double transform_tolerance = 0.1;  ///< how long a reading may wait for its transforms [s]
    std::size_t max_pending = 10000;   ///< readings waiting for tf beyond this are dropped
    /// a reading stamped more than this ahead of its arrival time is dropped [s] (>= 0)
    double future_tolerance = 0.5;
    /// frames whose newest stamp is remembered (>= 1); beyond, the least recently seen is forgotten
    std::size_t max_frames = 1024;
  };

  explicit ReadingBuffer(const Options& options);

  /**
   * @brief Checks and queues a reading for transform resolution, its frame id as tf2FrameId().
   * Drops (and counts) an empty frame id, a zero stamp, a stamp more than
   * Options::future_tolerance ahead of the reading's arrival time (such a reading never becomes
   * its frame's newest stamp), a stamp older than the last accepted reading of the same frame,
   * and overflow. Range validity is the converter's job. The newest stamp is remembered for at
   * most Options::max_frames frames: a new frame beyond that evicts the least recently seen one
   * (counted by framesEvicted()), whose next reading is then accepted as a first one.
   * @param[out] reason set to the drop reason when the reading is dropped (may be null)
   * @return true when queued
   */
  bool add(const TimedReading& reading, std::string* reason = nullptr);

  /// Counts a reading dropped before it reached the buffer (e.g. a NaN range).
  void countDrop(const std::string& reason, std::uint64_t count = 1);
  /// Counts a received reading (valid or not), for statistics.
  void countReceived(std::uint64_t count = 1)
  {
    received_ += count;
  }

  /**
   * @brief Resolves the queued readings whose transforms are available now, in arrival order;
   *        drops those that waited longer than the transform tolerance.
   * @param now the node's clock [s]
   * @param base_frame the robot base frame
   * @return the readings dropped by this call, each with its reason (for throttled warnings)
   */
  std::vector<std::pair<TimedReading, std::string>> resolve(double now, const std::string& base_frame,
                                                            const PoseLookup& lookup);

  /**
   * @brief Takes the next batch when k resolved readings are there and a batch is due
   *        (continuous mode, or a pending request in on-request mode). Continuous mode then
   *        slides the window by the stride; on-request mode clears the request.
   * @return false when no batch is due
   */
  bool takeBatch(Batch* batch);

  /// On-request mode: drops every buffered reading and arms one batch of k fresh readings.
  void requestBatch();
  /// True while an on-request batch is armed but not yet taken.
  bool batchRequested() const
  {
    return requested_;
  }

  /// Drops every buffered reading (not counted as drops; used by relocalization).
  void clear();

  std::uint64_t received() const
  {
    return received_;
  }
  std::uint64_t dropped() const;
  const std::map<std::string, std::uint64_t>& dropCounts() const
  {
    return drops_;
  }
  std::size_t pendingCount() const
  {
    return pending_.size();
  }
  std::size_t resolvedCount() const
  {
    return resolved_.size();
  }
  const Options& options() const
  {
    return options_;
  }
  /// Frames whose newest stamp is remembered (<= Options::max_frames).
  std::size_t trackedFrames() const
  {
    return frame_index_.size();
  }
  /// Frames forgotten to keep trackedFrames() within Options::max_frames.
  std::uint64_t framesEvicted() const
  {
    return frames_evicted_;
  }

private:
  /// Remembers @p stamp as the newest of @p frame (most recently seen), evicting beyond the cap.
  void rememberStamp(const std::string& frame, std::int64_t stamp);
  /// The newest accepted stamp of @p frame, or nullptr when not remembered.
  const std::int64_t* lastStamp(const std::string& frame) const;

  using FrameStamps = std::list<std::pair<std::string, std::int64_t>>;

  Options options_;
  std::deque<TimedReading> pending_;      ///< waiting for transforms, arrival order
  std::deque<ResolvedReading> resolved_;  ///< ready, arrival order
  FrameStamps last_stamps_;               ///< newest accepted stamp per frame [ns], most recently seen first
  std::unordered_map<std::string, FrameStamps::iterator> frame_index_;  ///< into last_stamps_
  std::uint64_t frames_evicted_ = 0;
  std::map<std::string, std::uint64_t> drops_;
  std::uint64_t received_ = 0;
  bool requested_ = false;
};

/// Builds the batch of @p readings: g_i = T(base at t_1)^-1 T(sensor at t_i). @p readings non-empty.
Batch makeBatch(const std::vector<ResolvedReading>& readings);

}  // namespace fdml_localization
