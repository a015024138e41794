#include "fuzz_messages.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace test
{
namespace
{
constexpr float kNan = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

MessageFuzzer::MessageFuzzer(ros::NodeHandle& nh, std::uint32_t seed, int beams_per_scan)
  : rng_(seed)
  , beams_per_scan_(beams_per_scan)
  , range_pub_(nh.advertise<sensor_msgs::Range>("range", 10000))
  , scan_pub_(nh.advertise<sensor_msgs::LaserScan>("scan", 1000))
{}

bool MessageFuzzer::waitForSubscribers(double timeout)
{
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < deadline)
  {
    if (range_pub_.getNumSubscribers() > 0 && scan_pub_.getNumSubscribers() > 0)
    {
      return true;
    }
    ros::WallDuration(0.01).sleep();
  }
  return false;
}

std::string MessageFuzzer::newFrame(const std::string& prefix)
{
  ++expected_.distinct_frames;
  return prefix + std::to_string(frame_counter_++);
}

sensor_msgs::Range MessageFuzzer::baseRange(const std::string& frame)
{
  sensor_msgs::Range msg;
  msg.header.frame_id = frame;
  msg.header.stamp = ros::Time::now();
  msg.field_of_view = 0.05f;
  msg.min_range = 0.1f;
  msg.max_range = 4.0f;
  msg.range = std::uniform_real_distribution<float>(0.1f, 4.0f)(rng_);
  return msg;
}

void MessageFuzzer::send(const sensor_msgs::Range& msg, const char* reason)
{
  ++expected_.received;
  if (reason != nullptr)
  {
    ++expected_.drops[reason];
  }
  range_pub_.publish(msg);
}

void MessageFuzzer::publishRange()
{
  const int kind = std::uniform_int_distribution<int>(0, 17)(rng_);
  sensor_msgs::Range msg = baseRange("range_sensor");
  if (kind < 8)
  {
    send(msg, breakRangeValues(kind, &msg));
  }
  else
  {
    publishOddHeaderRange(kind, msg);
  }
}

const char* MessageFuzzer::breakRangeValues(int kind, sensor_msgs::Range* msg)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  switch (kind)
  {
    case 0:
      msg->range = kNan;
      return "nan_range";
    case 1:
      msg->range = -kInf;
      return "negative_infinity";
    case 2:
      msg->range = -static_cast<float>(std::pow(10.0, 30.0 * unit(rng_)));
      return "negative_range";
    case 3:
      msg->min_range = kNan;
      return "invalid_limits";
    case 4:
      msg->max_range = unit(rng_) < 0.5 ? kNan : -kInf;
      return "invalid_limits";
    case 5:
      msg->max_range = 0.0f;
      return "invalid_limits";
    case 6:
      msg->range = static_cast<float>(0.1 * unit(rng_) * 0.99);
      return "below_min_range";
    default:
      msg->range = static_cast<float>(4.0 + std::pow(10.0, 30.0 * unit(rng_)));
      return "above_max_range";
  }
}

void MessageFuzzer::publishOddHeaderRange(int kind, sensor_msgs::Range msg)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  switch (kind)
  {
    case 8:
      msg.header.frame_id = unit(rng_) < 0.5 ? "" : (unit(rng_) < 0.5 ? "/" : "///");
      return send(msg, "empty_frame_id");
    case 9:
      msg.header.stamp = ros::Time();
      return send(msg, "zero_stamp");
    case 10:
      // From the future (an hour up to the end of ROS time), on the real sensor's frame.
      msg.header.stamp = unit(rng_) < 0.5 ? msg.header.stamp + ros::Duration(3600.0 + 1e6 * unit(rng_)) :
                                            ros::Time(4294967295u, 999999999u);
      return send(msg, "future_stamp");
    case 11:
      msg.header.frame_id = newFrame(unit(rng_) < 0.5 ? "ghost_" : "/ghost_");
      return send(msg, "unknown_frame");
    case 12:
      msg.header.frame_id = newFrame("ghost_fov_");
      msg.field_of_view = unit(rng_) < 0.5 ? kNan : (unit(rng_) < 0.5 ? kInf : -1.0f);
      ++expected_.odd_field_of_view;
      return send(msg, nullptr);
    case 13:
    case 14:
      // The same (unknown) frame twice, the second from the past: counted as going backwards.
      msg.header.frame_id = newFrame("past_");
      send(msg, "unknown_frame");
      msg.header.stamp = kind == 13 ? ros::Time(0, 1) : msg.header.stamp - ros::Duration(1e4 * unit(rng_) + 1.0);
      return send(msg, "stamp_backwards");
    case 15:
      msg.header.frame_id = newFrame("ghost_inf_");
      msg.range = kInf;  // a no-return: usable, but its frame is unknown
      return send(msg, "unknown_frame");
    default:
      msg.header.frame_id = newFrame("ghost_limits_");
      msg.min_range = -kInf;
      msg.max_range = kInf;
      return send(msg, "unknown_frame");
  }
}

void MessageFuzzer::breakHeader(sensor_msgs::LaserScan* scan)
{
  const float bad[] = { kNan, kInf, -kInf };
  const float pick = bad[std::uniform_int_distribution<int>(0, 2)(rng_)];
  switch (std::uniform_int_distribution<int>(0, 9)(rng_))
  {
    case 0:
      scan->angle_min = pick;
      break;
    case 1:
      scan->angle_max = pick;
      break;
    case 2:
      scan->angle_increment = pick;
      break;
    case 3:
      scan->angle_increment = 0.0f;
      break;
    case 4:
      scan->angle_max = scan->angle_min + 1.0f;
      scan->angle_increment = -0.05f;  // the wrong sign
      break;
    case 5:
      scan->time_increment = pick == -kInf ? -1e-3f : pick;
      break;
    case 6:
      scan->scan_time = pick;
      break;
    case 7:
      scan->range_min = pick == kInf ? -0.5f : pick;
      break;
    case 8:
      scan->range_max = pick;
      break;
    default:
      scan->range_max = 0.05f;  // below range_min
      break;
  }
}

void MessageFuzzer::fillBeams(sensor_msgs::LaserScan* scan, int beams)
{
  const float values[] = { kNan, -kInf, kInf, -1.0f, 0.05f, 6.0f, 1.0f, 2.5f, 4.9f };
  const char* reasons[] = {
    "nan_range", "negative_infinity", nullptr, "negative_range", "below_min_range", nullptr, nullptr, nullptr, nullptr
  };
  int usable = 0;
  for (int i = 0; i < beams; ++i)
  {
    const int v = std::uniform_int_distribution<int>(0, 8)(rng_);
    scan->ranges.push_back(values[v]);
    if (reasons[v] != nullptr)
    {
      ++expected_.drops[reasons[v]];
    }
    else
    {
      ++usable;  // +inf and above range_max are no-returns, the rest hits
    }
  }
  expected_.drops["unknown_frame"] += static_cast<std::uint64_t>(std::min(usable, beams_per_scan_));
}

void MessageFuzzer::publishScan()
{
  const int beams = std::uniform_int_distribution<int>(0, 40)(rng_);
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = newFrame(std::uniform_int_distribution<int>(0, 1)(rng_) ? "scan_" : "/scan_");
  scan.header.stamp = ros::Time::now();
  scan.angle_min = -1.0f;
  scan.angle_increment = 0.05f;
  scan.angle_max = scan.angle_min + static_cast<float>(std::max(0, beams - 1)) * scan.angle_increment;
  scan.time_increment = 1e-4f;
  scan.scan_time = 0.01f;
  scan.range_min = 0.1f;
  scan.range_max = 5.0f;
  if (std::uniform_int_distribution<int>(0, 1)(rng_) == 0)
  {
    breakHeader(&scan);
    scan.ranges.assign(static_cast<std::size_t>(beams), 1.0f);
    const std::uint64_t counted = static_cast<std::uint64_t>(std::max(1, beams));
    expected_.received += counted;
    expected_.drops["invalid_scan"] += counted;
  }
  else
  {
    fillBeams(&scan, beams);
    expected_.received += static_cast<std::uint64_t>(beams);
  }
  scan_pub_.publish(scan);
}

}  // namespace test
}  // namespace fdml_localization
