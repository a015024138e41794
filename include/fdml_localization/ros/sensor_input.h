/**
 * @file sensor_input.h
 * @brief The localizer node's input side: REP-117 checks of Range and LaserScan messages,
 *        buffering (callbacks only check and buffer), tf resolution of each reading at its own
 *        stamp, and batches queued for the worker.
 */
#pragma once

#include "fdml_localization/ros/node_state.h"
#include "fdml_localization/ros/params.h"
#include "fdml_localization/ros/reading_buffer.h"

#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>
#include <tf2_ros/buffer.h>

#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace fdml_localization
{
/**
 * @brief A sensor_msgs/Range as a reading, with REP-117 semantics: +inf is a no-return reading;
 *        NaN, -inf ("too close") and values outside [min_range, max_range] are dropped.
 * @param received arrival time on the node's clock [s]
 * @param[out] reading set when the reading is usable
 * @param[out] reason the drop reason (a drop_reason:: identifier) when it is not
 * @return true when usable
 */
bool rangeToReading(const sensor_msgs::Range& msg, double received, TimedReading* reading, std::string* reason);

/// The longest scan accepted: time_increment * (beams - 1) and scan_time at most this [s].
constexpr double kMaxScanDuration = 60.0;
/// The largest beam angle accepted in a LaserScan, in absolute value: 4 pi [rad].
constexpr double kMaxScanAngle = 4.0 * 3.14159265358979323846;

/**
 * @brief What is wrong with a LaserScan's header fields, naming the field; "" when usable.
 *        Requires finite angle_min, angle_max and angle_increment, a non-zero increment whose
 *        sign matches angle_max - angle_min, every beam angle (angle_min + i * angle_increment)
 *        and angle_max within kMaxScanAngle in absolute value, finite non-negative
 *        time_increment and scan_time with the scan lasting at most kMaxScanDuration, and
 *        finite 0 <= range_min < range_max.
 */
std::string scanHeaderProblem(const sensor_msgs::LaserScan& msg);

/**
 * @brief Up to @p beams evenly spaced usable beams of a scan whose header passes
 *        scanHeaderProblem() (REP-117 per beam: +inf, and a finite value above range_max, is a
 *        no-return; NaN, -inf, negative values and values below range_min are flagged invalid
 *        by the driver and dropped, never turned into no-returns). Beam i is stamped
 *        header.stamp + i * time_increment and posed (0, 0, angle_min + i * angle_increment)
 *        in the scan frame.
 * @param[out] drops counts of unusable beams by reason; a scan with a bad header counts all its
 *             beams (at least one) as drop_reason::kInvalidScan and gives no reading
 * @param[out] header_problem set to scanHeaderProblem() when not empty (may be null)
 */
std::vector<TimedReading> scanToReadings(const sensor_msgs::LaserScan& msg, int beams, double received,
                                         std::map<std::string, std::uint64_t>* drops,
                                         std::string* header_problem = nullptr);

/// The reading buffer's options from the node's parameters.
ReadingBuffer::Options bufferOptions(const Params& params);

/**
 * @brief Subscribes to the range and scan topics; callbacks check and buffer readings in the
 *        shared state; process() (on the node's timer) resolves their tf without waiting and
 *        queues complete batches for the worker.
 */
class SensorInput
{
public:
  SensorInput(ros::NodeHandle& nh, const Params& params, NodeState& state, const tf2_ros::Buffer& tf);

  /// Resolves buffered readings in the odom frame and queues every complete batch.
  void process();

private:
  void rangeCallback(const sensor_msgs::Range::ConstPtr& msg);
  void scanCallback(const sensor_msgs::LaserScan::ConstPtr& msg);
  LookupStatus lookupInOdom(const std::string& frame, std::int64_t stamp, core::Pose2* pose) const;
  void warnDropped(const std::string& frame, const std::string& reason) const;

  const Params& params_;
  NodeState& state_;
  const tf2_ros::Buffer& tf_;
  ros::Subscriber range_sub_;
  ros::Subscriber scan_sub_;
};

}  // namespace fdml_localization
