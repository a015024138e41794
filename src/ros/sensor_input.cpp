#include "fdml_localization/ros/sensor_input.h"

#include "fdml_localization/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <utility>

namespace fdml_localization
{
namespace
{
/// REP-117 check of one range value; returns nullptr when usable (+inf included).
const char* rangeProblem(double range, double min_range, double max_range)
{
  if (std::isnan(min_range) || std::isnan(max_range) || !(max_range > 0.0) || max_range < min_range)
  {
    return drop_reason::kInvalidLimits;
  }
  if (std::isnan(range))
  {
    return drop_reason::kNanRange;
  }
  if (range == -core::kInf)
  {
    return drop_reason::kNegativeInfinity;
  }
  if (range == core::kInf)
  {
    return nullptr;
  }
  if (range < 0.0)
  {
    return drop_reason::kNegativeRange;
  }
  if (range < min_range)
  {
    return drop_reason::kBelowMinRange;
  }
  if (range > max_range)
  {
    return drop_reason::kAboveMaxRange;
  }
  return nullptr;
}

/// One warning per run for frame ids with a leading '/' (the buffer strips it, see tf2FrameId()).
void noteLeadingSlash(const std::string& frame_id)
{
  if (!frame_id.empty() && frame_id[0] == '/')
  {
    ROS_WARN_ONCE("fdml_localizer: sensor frame ids with a leading '/' (\"%s\") are used without it, as tf2 "
                  "expects (warned once)",
                  frame_id.c_str());
  }
}
}  // namespace

bool rangeToReading(const sensor_msgs::Range& msg, double received, TimedReading* reading, std::string* reason)
{
  const char* problem = rangeProblem(msg.range, msg.min_range, msg.max_range);
  if (problem)
  {
    *reason = problem;
    return false;
  }
  if (!fieldOfViewToHalfAngle(msg.field_of_view, &reading->half_angle))
  {
    *reason = drop_reason::kInvalidFieldOfView;
    return false;
  }
  reading->frame_id = msg.header.frame_id;
  reading->stamp = static_cast<std::int64_t>(msg.header.stamp.toNSec());
  reading->beam = core::Pose2();
  reading->range = msg.range;
  reading->max_range = msg.max_range;
  reading->received = received;
  return true;
}

std::string scanHeaderProblem(const sensor_msgs::LaserScan& msg)
{
  const auto field = [](const char* name, double value, const char* allowed) {
    std::ostringstream out;
    out << name << " = " << value << ": " << allowed;
    return out.str();
  };
  const double beams = msg.ranges.empty() ? 0.0 : static_cast<double>(msg.ranges.size() - 1);
  const double last_angle = msg.angle_min + beams * msg.angle_increment;
  const std::pair<const char*, double> angles[] = { { "angle_min", msg.angle_min },
                                                    { "angle_max", msg.angle_max },
                                                    { "angle_increment", msg.angle_increment } };
  for (const auto& angle : angles)
  {
    if (!std::isfinite(angle.second))
    {
      return field(angle.first, angle.second, "must be finite [rad]");
    }
  }
  const double span = static_cast<double>(msg.angle_max) - msg.angle_min;
  if (msg.angle_increment == 0.0 || (span != 0.0 && (span > 0.0) != (msg.angle_increment > 0.0)))
  {
    return field("angle_increment", msg.angle_increment, "must be non-zero, its sign that of angle_max - angle_min");
  }
  for (const auto& angle : { angles[0], angles[1] })
  {
    if (std::fabs(angle.second) > kMaxScanAngle)
    {
      return field(angle.first, angle.second, "must lie within [-4 pi, 4 pi] rad");
    }
  }
  if (!(std::fabs(last_angle) <= kMaxScanAngle))
  {
    return field("angle_increment", msg.angle_increment, "puts the last beam beyond [-4 pi, 4 pi] rad");
  }
  if (!(msg.time_increment >= 0.0) || !(beams * msg.time_increment <= kMaxScanDuration))
  {
    return field("time_increment", msg.time_increment, "must be >= 0, the scan lasting at most 60 s [s]");
  }
  if (!(msg.scan_time >= 0.0) || !(msg.scan_time <= kMaxScanDuration))
  {
    return field("scan_time", msg.scan_time, "must be in [0, 60] s");
  }
  if (!(msg.range_min >= 0.0) || !std::isfinite(msg.range_min))
  {
    return field("range_min", msg.range_min, "must be finite and >= 0 [m]");
  }
  if (!std::isfinite(msg.range_max) || !(msg.range_max > msg.range_min))
  {
    return field("range_max", msg.range_max, "must be finite and > range_min [m]");
  }
  return "";
}

std::vector<TimedReading> scanToReadings(const sensor_msgs::LaserScan& msg, int beams, double received,
                                         std::map<std::string, std::uint64_t>* drops, std::string* header_problem)
{
  std::vector<TimedReading> out;
  const std::string problem = scanHeaderProblem(msg);
  if (!problem.empty())
  {
    (*drops)[drop_reason::kInvalidScan] += std::max<std::size_t>(1, msg.ranges.size());
    if (header_problem)
    {
      *header_problem = problem;
    }
    return out;
  }
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < msg.ranges.size(); ++i)
  {
    const double range = msg.ranges[i];
    // Above range_max is a no-return (REP-117); below range_min is flagged invalid.
    const char* beam_problem = range > msg.range_max ? nullptr : rangeProblem(range, msg.range_min, msg.range_max);
    if (beam_problem)
    {
      ++(*drops)[beam_problem];
      continue;
    }
    usable.push_back(i);
  }
  if (usable.empty() || beams <= 0)
  {
    return out;
  }
  const std::size_t n = std::min(usable.size(), static_cast<std::size_t>(beams));
  for (std::size_t j = 0; j < n; ++j)
  {
    const std::size_t i = usable[j * usable.size() / n];
    TimedReading reading;
    reading.frame_id = msg.header.frame_id;
    // Bounded by kMaxScanDuration (scanHeaderProblem), so the rounding cannot overflow.
    reading.stamp = static_cast<std::int64_t>(msg.header.stamp.toNSec()) +
                    std::llround(static_cast<double>(i) * msg.time_increment * 1e9);
    reading.beam = core::Pose2(0.0, 0.0, core::wrapAngle(msg.angle_min + static_cast<double>(i) * msg.angle_increment));
    reading.range = msg.ranges[i] > msg.range_max ? core::kInf : msg.ranges[i];
    reading.max_range = msg.range_max;
    reading.received = received;
    out.push_back(reading);
  }
  return out;
}

ReadingBuffer::Options bufferOptions(const Params& params)
{
  ReadingBuffer::Options options;
  options.batch_size = params.measurements_per_batch;
  options.stride = params.batch_stride;
  options.continuous = solveMode(params) == SolveMode::Continuous;
  options.transform_tolerance = params.transform_tolerance;
  options.future_tolerance = params.future_tolerance;
  options.max_frames = static_cast<std::size_t>(std::max(1, params.max_sensor_frames));
  return options;
}

SensorInput::SensorInput(ros::NodeHandle& nh, const Params& params, NodeState& state, const tf2_ros::Buffer& tf)
  : params_(params), state_(state), tf_(tf)
{
  // Queues of about a second at 1 kHz (Range) and 100 Hz (LaserScan): bounded, and deep enough
  // that a short stall of the node does not lose readings uncounted.
  range_sub_ = nh.subscribe(params_.range_topic, 1000, &SensorInput::rangeCallback, this);
  scan_sub_ = nh.subscribe(params_.scan_topic, 100, &SensorInput::scanCallback, this);
}

void SensorInput::rangeCallback(const sensor_msgs::Range::ConstPtr& msg)
{
  noteLeadingSlash(msg->header.frame_id);
  TimedReading reading;
  std::string reason;
  const bool usable = rangeToReading(*msg, ros::Time::now().toSec(), &reading, &reason);
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    state_.buffer.countReceived();
    if (usable)
    {
      state_.buffer.add(reading, &reason);
    }
    else
    {
      state_.buffer.countDrop(reason);
    }
  }
  if (!reason.empty())
  {
    ROS_WARN_THROTTLE(5.0, "fdml_localizer: dropped a Range reading from frame \"%s\" (range %g, stamp %.3f): %s",
                      msg->header.frame_id.c_str(), msg->range, msg->header.stamp.toSec(), reason.c_str());
  }
}

void SensorInput::scanCallback(const sensor_msgs::LaserScan::ConstPtr& msg)
{
  noteLeadingSlash(msg->header.frame_id);
  std::map<std::string, std::uint64_t> drops;
  std::string header_problem;
  const std::vector<TimedReading> readings =
      scanToReadings(*msg, params_.beams_per_scan, ros::Time::now().toSec(), &drops, &header_problem);
  std::string reason;
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    state_.buffer.countReceived(header_problem.empty() ? msg->ranges.size() :
                                                         std::max<std::size_t>(1, msg->ranges.size()));
    for (const auto& drop : drops)
    {
      state_.buffer.countDrop(drop.first, drop.second);
    }
    for (const TimedReading& reading : readings)
    {
      state_.buffer.add(reading, &reason);
    }
  }
  if (!header_problem.empty())
  {
    ROS_WARN_THROTTLE(5.0, "fdml_localizer: dropped a LaserScan from frame \"%s\" (stamp %.3f): %s",
                      msg->header.frame_id.c_str(), msg->header.stamp.toSec(), header_problem.c_str());
  }
  if (!reason.empty())
  {
    ROS_WARN_THROTTLE(5.0, "fdml_localizer: dropped LaserScan beams from frame \"%s\": %s",
                      msg->header.frame_id.c_str(), reason.c_str());
  }
}

LookupStatus SensorInput::lookupInOdom(const std::string& frame, std::int64_t stamp, core::Pose2* pose) const
{
  const ros::Time time = stampToTime(stamp);
  try
  {
    if (!tf_.canTransform(params_.odom_frame_id, frame, time))
    {
      return tf_._frameExists(frame) ? LookupStatus::NotYet : LookupStatus::UnknownFrame;
    }
    *pose = fromTransformMsg(tf_.lookupTransform(params_.odom_frame_id, frame, time).transform);
    return LookupStatus::Ok;
  }
  catch (const tf2::TransformException&)
  {
    return LookupStatus::NotYet;
  }
}

void SensorInput::warnDropped(const std::string& frame, const std::string& reason) const
{
  ROS_WARN_THROTTLE(5.0,
                    "fdml_localizer: dropped a reading from frame \"%s\": %s (no tf %s -> %s and %s -> %s at its "
                    "stamp within ~transform_tolerance = %g s)",
                    frame.c_str(), reason.c_str(), params_.odom_frame_id.c_str(), params_.base_frame_id.c_str(),
                    params_.odom_frame_id.c_str(), frame.c_str(), params_.transform_tolerance);
}

void SensorInput::process()
{
  std::vector<std::pair<TimedReading, std::string>> dropped;
  bool queued = false;
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    const auto lookup = [this](const std::string& frame, std::int64_t stamp, core::Pose2* pose) {
      return lookupInOdom(frame, stamp, pose);
    };
    dropped = state_.buffer.resolve(ros::Time::now().toSec(), params_.base_frame_id, lookup);
    Batch batch;
    while (state_.buffer.takeBatch(&batch))
    {
      Job job;
      job.from_sensors = true;
      job.generation = state_.generation;
      job.readings = batch.readings;
      job.batch = std::move(batch);
      state_.queueBatchLocked(std::move(job));
      queued = true;
    }
  }
  for (const auto& drop : dropped)
  {
    warnDropped(drop.first.frame_id, drop.second);
  }
  if (queued)
  {
    state_.work_ready.notify_one();
  }
}

}  // namespace fdml_localization
