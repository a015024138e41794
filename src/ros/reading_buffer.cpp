#include "fdml_localization/ros/reading_buffer.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fdml_localization
{
ReadingBuffer::ReadingBuffer(const Options& options) : options_(options)
{
  options_.batch_size = std::max(1, options_.batch_size);
  options_.stride = std::min(std::max(1, options_.stride), options_.batch_size);
  options_.max_frames = std::max<std::size_t>(1, options_.max_frames);
  if (!(options_.future_tolerance >= 0.0))
  {
    options_.future_tolerance = 0.0;
  }
}

std::string tf2FrameId(const std::string& frame_id)
{
  const std::size_t first = frame_id.find_first_not_of('/');
  return first == std::string::npos ? std::string() : frame_id.substr(first);
}

bool ReadingBuffer::add(const TimedReading& received_reading, std::string* reason)
{
  TimedReading reading = received_reading;
  reading.frame_id = tf2FrameId(received_reading.frame_id);
  const char* why = nullptr;
  if (reading.frame_id.empty())
  {
    why = drop_reason::kEmptyFrameId;
  }
  else if (reading.stamp <= 0)
  {
    why = drop_reason::kZeroStamp;
  }
  else if (static_cast<double>(reading.stamp) * 1e-9 > reading.received + options_.future_tolerance)
  {
    why = drop_reason::kFutureStamp;
  }
  else if (pending_.size() >= options_.max_pending)
  {
    why = drop_reason::kBufferOverflow;
  }
  else
  {
    const std::int64_t* last = lastStamp(reading.frame_id);
    if (last != nullptr && reading.stamp < *last)
    {
      why = drop_reason::kStampBackwards;
    }
  }
  if (why)
  {
    countDrop(why);
    if (reason)
    {
      *reason = why;
    }
    return false;
  }
  rememberStamp(reading.frame_id, reading.stamp);
  pending_.push_back(std::move(reading));
  return true;
}

const std::int64_t* ReadingBuffer::lastStamp(const std::string& frame) const
{
  const auto it = frame_index_.find(frame);
  return it == frame_index_.end() ? nullptr : &it->second->second;
}

void ReadingBuffer::rememberStamp(const std::string& frame, std::int64_t stamp)
{
  const auto it = frame_index_.find(frame);
  if (it != frame_index_.end())
  {
    it->second->second = stamp;
    last_stamps_.splice(last_stamps_.begin(), last_stamps_, it->second);
    return;
  }
  last_stamps_.emplace_front(frame, stamp);
  frame_index_.emplace(frame, last_stamps_.begin());
  while (frame_index_.size() > options_.max_frames)
  {
    frame_index_.erase(last_stamps_.back().first);
    last_stamps_.pop_back();
    ++frames_evicted_;
  }
}

void ReadingBuffer::countDrop(const std::string& reason, std::uint64_t count)
{
  drops_[reason] += count;
}

std::uint64_t ReadingBuffer::dropped() const
{
  std::uint64_t total = 0;
  for (const auto& entry : drops_)
  {
    total += entry.second;
  }
  return total;
}

std::vector<std::pair<TimedReading, std::string>> ReadingBuffer::resolve(double now, const std::string& base_frame,
                                                                         const PoseLookup& lookup)
{
  std::vector<std::pair<TimedReading, std::string>> dropped_now;
  std::deque<TimedReading> still_pending;
  for (TimedReading& reading : pending_)
  {
    ResolvedReading resolved;
    resolved.raw = reading;
    core::Pose2 sensor;
    LookupStatus sensor_status = lookup(reading.frame_id, reading.stamp, &sensor);
    LookupStatus base_status = LookupStatus::NotYet;
    if (sensor_status == LookupStatus::Ok)
    {
      base_status = lookup(base_frame, reading.stamp, &resolved.base_in_odom);
    }
    if (sensor_status == LookupStatus::Ok && base_status == LookupStatus::Ok)
    {
      resolved.sensor_in_odom = core::compose(sensor, reading.beam);
      resolved_.push_back(resolved);
      continue;
    }
    if (now - reading.received > options_.transform_tolerance)
    {
      const bool unknown = sensor_status == LookupStatus::UnknownFrame || base_status == LookupStatus::UnknownFrame;
      const char* why = unknown ? drop_reason::kUnknownFrame : drop_reason::kTransformUnavailable;
      countDrop(why);
      dropped_now.emplace_back(reading, why);
      continue;
    }
    still_pending.push_back(reading);
  }
  pending_.swap(still_pending);

  // Idle on-request mode keeps only the newest k readings (they are never used: a request
  // clears them), so the buffer stays bounded.
  if (!options_.continuous && !requested_)
  {
    while (resolved_.size() > static_cast<std::size_t>(options_.batch_size))
    {
      resolved_.pop_front();
    }
  }
  return dropped_now;
}

bool ReadingBuffer::takeBatch(Batch* batch)
{
  const std::size_t k = static_cast<std::size_t>(options_.batch_size);
  if (resolved_.size() < k || (!options_.continuous && !requested_))
  {
    return false;
  }
  std::vector<ResolvedReading> readings(resolved_.begin(), resolved_.begin() + static_cast<std::ptrdiff_t>(k));
  *batch = makeBatch(readings);
  if (options_.continuous)
  {
    resolved_.erase(resolved_.begin(), resolved_.begin() + options_.stride);
  }
  else
  {
    resolved_.erase(resolved_.begin(), resolved_.begin() + static_cast<std::ptrdiff_t>(k));
    requested_ = false;
  }
  return true;
}

void ReadingBuffer::requestBatch()
{
  clear();
  requested_ = true;
}

void ReadingBuffer::clear()
{
  pending_.clear();
  resolved_.clear();
}

Batch makeBatch(const std::vector<ResolvedReading>& readings)
{
  Batch batch;
  batch.sources = readings;
  const ResolvedReading& first = readings.front();
  batch.first_stamp = first.raw.stamp;
  batch.base_first = first.base_in_odom;
  batch.newest_stamp = first.raw.stamp;
  batch.base_newest = first.base_in_odom;
  const core::Pose2 odom_to_base = core::inverse(first.base_in_odom);
  for (const ResolvedReading& r : readings)
  {
    core::Reading reading;
    reading.offset = core::compose(odom_to_base, r.sensor_in_odom);
    reading.range = r.raw.range;
    reading.max_range = r.raw.max_range;
    reading.half_angle = r.raw.half_angle;
    batch.readings.push_back(reading);
    if (r.raw.stamp > batch.newest_stamp)
    {
      batch.newest_stamp = r.raw.stamp;
      batch.base_newest = r.base_in_odom;
    }
  }
  return batch;
}

}  // namespace fdml_localization
