#include "fdml_localization/ros/sensor_input.h"

#include "fdml_localization/ros/conversions.h"

#include <algorithm>
#include <cmath>
#include <memory>
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

std::vector<TimedReading> scanToReadings(const sensor_msgs::LaserScan& msg, int beams, double received,
                                         std::map<std::string, std::uint64_t>* drops)
{
  std::vector<std::size_t> usable;
  for (std::size_t i = 0; i < msg.ranges.size(); ++i)
  {
    const char* problem = rangeProblem(msg.ranges[i], msg.range_min, msg.range_max);
    if (problem)
    {
      ++(*drops)[problem];
      continue;
    }
    usable.push_back(i);
  }
  std::vector<TimedReading> out;
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
    reading.stamp = static_cast<std::int64_t>(msg.header.stamp.toNSec()) +
                    std::llround(static_cast<double>(i) * msg.time_increment * 1e9);
    reading.beam = core::Pose2(0.0, 0.0, core::wrapAngle(msg.angle_min + static_cast<double>(i) * msg.angle_increment));
    reading.range = msg.ranges[i];
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
  return options;
}

SensorInput::SensorInput(ros::NodeHandle& nh, const Params& params, NodeState& state, const tf2_ros::Buffer& tf)
  : params_(params), state_(state), tf_(tf)
{
  range_sub_ = nh.subscribe(params_.range_topic, 100, &SensorInput::rangeCallback, this);
  scan_sub_ = nh.subscribe(params_.scan_topic, 10, &SensorInput::scanCallback, this);
}

void SensorInput::rangeCallback(const sensor_msgs::Range::ConstPtr& msg)
{
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
  std::map<std::string, std::uint64_t> drops;
  const std::vector<TimedReading> readings =
      scanToReadings(*msg, params_.beams_per_scan, ros::Time::now().toSec(), &drops);
  std::string reason;
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    state_.buffer.countReceived(msg->ranges.size());
    for (const auto& drop : drops)
    {
      state_.buffer.countDrop(drop.first, drop.second);
    }
    for (const TimedReading& reading : readings)
    {
      state_.buffer.add(reading, &reason);
    }
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
      std::unique_ptr<Job> job(new Job);
      job->from_sensors = true;
      job->generation = state_.generation;
      job->readings = batch.readings;
      job->batch = std::move(batch);
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
