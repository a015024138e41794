/**
 * @file fuzz_messages.h
 * @brief Seeded generators of malformed and odd Range and LaserScan messages for the localizer
 *        node's fuzz rostest, each with the drop reason the node must count for it (derived
 *        from REP-117 and the documented checks, independently of the node's code).
 */
#pragma once

#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>

#include <cstdint>
#include <map>
#include <random>
#include <string>

namespace fdml_localization
{
namespace test
{
/// What the node must have counted for the messages published so far.
struct FuzzExpectation
{
  std::uint64_t received = 0;                  ///< "readings received"
  std::map<std::string, std::uint64_t> drops;  ///< "dropped: <reason>"
  std::uint64_t odd_field_of_view = 0;         ///< unknown_frame, unless a field-of-view check drops them
  std::uint64_t distinct_frames = 0;           ///< frame ids used
};

class MessageFuzzer
{
public:
  /// @param beams_per_scan the node's ~beams_per_scan
  MessageFuzzer(ros::NodeHandle& nh, std::uint32_t seed, int beams_per_scan);

  /// Waits until the node subscribes to both topics; false on timeout [s].
  bool waitForSubscribers(double timeout);
  /// Publishes one random malformed or odd Range (two for a stamp going backwards).
  void publishRange();
  /// Publishes one random LaserScan: a broken header, or beams with NaN, inf and out-of-range values.
  void publishScan();

  const FuzzExpectation& expected() const
  {
    return expected_;
  }

private:
  sensor_msgs::Range baseRange(const std::string& frame);
  std::string newFrame(const std::string& prefix);
  void send(const sensor_msgs::Range& msg, const char* reason);
  /// Breaks a value field of @p msg (kind in [0, 7]); returns the drop reason.
  const char* breakRangeValues(int kind, sensor_msgs::Range* msg);
  /// Publishes @p msg with an odd frame or stamp (kind in [8, 17]).
  void publishOddHeaderRange(int kind, sensor_msgs::Range msg);
  /// Breaks one header field of @p scan at random.
  void breakHeader(sensor_msgs::LaserScan* scan);
  /// Fills the beams at random and adds their expected drops.
  void fillBeams(sensor_msgs::LaserScan* scan, int beams);

  std::mt19937 rng_;
  int beams_per_scan_;
  ros::Publisher range_pub_;
  ros::Publisher scan_pub_;
  FuzzExpectation expected_;
  std::uint64_t frame_counter_ = 0;
};

}  // namespace test
}  // namespace fdml_localization
