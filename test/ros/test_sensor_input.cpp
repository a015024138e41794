// The localizer node's message checks (no roscore needed): Range and LaserScan to readings with
// REP-117 semantics, and the LaserScan header checks.
#include "fdml_localization/ros/sensor_input.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <utility>

namespace fdml_localization
{
namespace
{
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr float kNanF = std::numeric_limits<float>::quiet_NaN();
constexpr float kInfF = std::numeric_limits<float>::infinity();

sensor_msgs::Range rangeMsg(double range)
{
  sensor_msgs::Range msg;
  msg.header.frame_id = "sonar";
  msg.header.stamp = ros::Time(12.5);
  msg.min_range = 0.05;
  msg.max_range = 4.0;
  msg.range = static_cast<float>(range);
  return msg;
}

/// A valid 360-beam scan of 3 m everywhere, one beam per degree over a full turn.
sensor_msgs::LaserScan scanMsg()
{
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = "laser";
  scan.header.stamp = ros::Time(100.0);
  scan.angle_min = static_cast<float>(-core::kPi);
  scan.angle_max = static_cast<float>(core::kPi - core::kTwoPi / 360.0);
  scan.angle_increment = static_cast<float>(core::kTwoPi / 360.0);
  scan.time_increment = 0.001f;
  scan.scan_time = 0.36f;
  scan.range_min = 0.1f;
  scan.range_max = 10.0f;
  scan.ranges.assign(360, 3.0f);
  return scan;
}

TEST(SensorInput, RangeFollowsRep117)
{
  TimedReading reading;
  std::string reason;
  ASSERT_TRUE(rangeToReading(rangeMsg(2.0), 13.0, &reading, &reason));
  EXPECT_EQ(reading.frame_id, "sonar");
  EXPECT_EQ(reading.stamp, 12500000000);
  EXPECT_EQ(reading.range, 2.0);
  EXPECT_EQ(reading.max_range, 4.0);
  EXPECT_EQ(reading.received, 13.0);
  EXPECT_EQ(reading.beam.x, 0.0);
  EXPECT_EQ(reading.beam.y, 0.0);
  EXPECT_EQ(reading.beam.theta, 0.0);

  ASSERT_TRUE(rangeToReading(rangeMsg(core::kInf), 13.0, &reading, &reason));
  EXPECT_EQ(reading.range, core::kInf);

  const std::pair<double, const char*> dropped[] = {
    { kNan, drop_reason::kNanRange },      { -core::kInf, drop_reason::kNegativeInfinity },
    { -1.0, drop_reason::kNegativeRange }, { 0.01, drop_reason::kBelowMinRange },
    { 4.5, drop_reason::kAboveMaxRange },
  };
  for (const auto& entry : dropped)
  {
    reason.clear();
    EXPECT_FALSE(rangeToReading(rangeMsg(entry.first), 13.0, &reading, &reason)) << entry.first;
    EXPECT_EQ(reason, entry.second);
  }
  sensor_msgs::Range bad_limits = rangeMsg(1.0);
  bad_limits.max_range = 0.0;
  EXPECT_FALSE(rangeToReading(bad_limits, 13.0, &reading, &reason));
  EXPECT_EQ(reason, drop_reason::kInvalidLimits);
  // The limits themselves are inclusive.
  EXPECT_TRUE(rangeToReading(rangeMsg(4.0), 13.0, &reading, &reason));
}

TEST(SensorInput, ScanTakesEvenlySpacedUsableBeams)
{
  sensor_msgs::LaserScan scan = scanMsg();
  for (int i = 0; i < 360; i += 4)
  {
    scan.ranges[static_cast<std::size_t>(i)] = kNanF;  // 90 NaN beams
  }
  scan.ranges[1] = kInfF;   // a no-return
  scan.ranges[2] = 20.0f;   // above range_max: a no-return too (REP-117)
  scan.ranges[3] = 0.05f;   // below range_min: flagged invalid, dropped
  scan.ranges[5] = -kInfF;  // too close: dropped

  std::map<std::string, std::uint64_t> drops;
  const std::vector<TimedReading> readings = scanToReadings(scan, 10, 101.0, &drops);
  EXPECT_EQ(drops[drop_reason::kNanRange], 90u);
  EXPECT_EQ(drops[drop_reason::kBelowMinRange], 1u);
  EXPECT_EQ(drops[drop_reason::kNegativeInfinity], 1u);
  EXPECT_EQ(drops.count(drop_reason::kAboveMaxRange), 0u);
  ASSERT_EQ(readings.size(), 10u);
  // 268 usable beams; reading j is usable beam floor(j * 268 / 10).
  std::vector<int> usable;
  for (int i = 0; i < 360; ++i)
  {
    if (i % 4 != 0 && i != 3 && i != 5)
    {
      usable.push_back(i);
    }
  }
  ASSERT_EQ(usable.size(), 268u);
  for (std::size_t j = 0; j < readings.size(); ++j)
  {
    const int i = usable[j * usable.size() / readings.size()];
    EXPECT_EQ(readings[j].frame_id, "laser");
    EXPECT_NEAR(static_cast<double>(readings[j].stamp), 100e9 + i * 1e6, 1e3);
    EXPECT_NEAR(core::angleDiff(readings[j].beam.theta, -core::kPi + i * core::kTwoPi / 360.0), 0.0, 1e-5);
    EXPECT_EQ(readings[j].range, i == 1 || i == 2 ? core::kInf : 3.0);
    EXPECT_EQ(readings[j].max_range, 10.0);
  }
  EXPECT_EQ(readings[0].range, core::kInf);  // beam 1 is the first usable one

  // Fewer usable beams than asked: all of them; the above-range one is a no-return.
  drops.clear();
  const std::vector<TimedReading> all = scanToReadings(scan, 1000, 101.0, &drops);
  ASSERT_EQ(all.size(), 268u);
  EXPECT_EQ(all[1].range, core::kInf);
  for (const TimedReading& reading : all)
  {
    EXPECT_TRUE(reading.range == core::kInf || reading.range == 3.0) << reading.range;
  }
}

TEST(SensorInput, InvalidBeamsAreNeverNoReturns)
{
  // A scan of nothing but beams the driver flags as invalid gives no reading at all.
  sensor_msgs::LaserScan scan = scanMsg();
  for (std::size_t i = 0; i < scan.ranges.size(); ++i)
  {
    scan.ranges[i] = i % 3 == 0 ? kNanF : (i % 3 == 1 ? 0.05f : -1.0f);
  }
  std::map<std::string, std::uint64_t> drops;
  EXPECT_TRUE(scanToReadings(scan, 1000, 101.0, &drops).empty());
  EXPECT_EQ(drops[drop_reason::kNanRange] + drops[drop_reason::kBelowMinRange] + drops[drop_reason::kNegativeRange],
            360u);
}

TEST(SensorInput, ScanHeaderChecksNameTheField)
{
  struct Case
  {
    const char* field;
    std::function<void(sensor_msgs::LaserScan&)> set;
  };
  const std::vector<Case> cases = {
    { "angle_min", [](sensor_msgs::LaserScan& s) { s.angle_min = kInfF; } },
    { "angle_min", [](sensor_msgs::LaserScan& s) { s.angle_min = kNanF; } },
    { "angle_max", [](sensor_msgs::LaserScan& s) { s.angle_max = -kInfF; } },
    { "angle_increment", [](sensor_msgs::LaserScan& s) { s.angle_increment = kNanF; } },
    { "angle_increment", [](sensor_msgs::LaserScan& s) { s.angle_increment = 0.0f; } },
    { "angle_increment", [](sensor_msgs::LaserScan& s) { s.angle_increment = -0.01f; } },
    { "angle_increment", [](sensor_msgs::LaserScan& s) { s.angle_increment = 3e38f; } },
    { "time_increment", [](sensor_msgs::LaserScan& s) { s.time_increment = kNanF; } },
    { "time_increment", [](sensor_msgs::LaserScan& s) { s.time_increment = kInfF; } },
    { "time_increment", [](sensor_msgs::LaserScan& s) { s.time_increment = -1e-3f; } },
    { "time_increment", [](sensor_msgs::LaserScan& s) { s.time_increment = 1e30f; } },
    { "scan_time", [](sensor_msgs::LaserScan& s) { s.scan_time = kNanF; } },
    { "scan_time", [](sensor_msgs::LaserScan& s) { s.scan_time = -0.1f; } },
    { "range_min", [](sensor_msgs::LaserScan& s) { s.range_min = -0.1f; } },
    { "range_min", [](sensor_msgs::LaserScan& s) { s.range_min = kNanF; } },
    { "range_max", [](sensor_msgs::LaserScan& s) { s.range_max = kInfF; } },
    { "range_max", [](sensor_msgs::LaserScan& s) { s.range_max = kNanF; } },
    { "range_max", [](sensor_msgs::LaserScan& s) { s.range_max = 0.1f; } },
  };
  EXPECT_EQ(scanHeaderProblem(scanMsg()), "");
  for (const Case& c : cases)
  {
    sensor_msgs::LaserScan scan = scanMsg();
    c.set(scan);
    const std::string problem = scanHeaderProblem(scan);
    EXPECT_EQ(problem.rfind(c.field, 0), 0u) << c.field << ": " << problem;
    // Dropped whole, every beam counted as an invalid scan.
    std::map<std::string, std::uint64_t> drops;
    std::string reported;
    EXPECT_TRUE(scanToReadings(scan, 10, 101.0, &drops, &reported).empty()) << c.field;
    EXPECT_EQ(reported, problem);
    EXPECT_EQ(drops.size(), 1u);
    EXPECT_EQ(drops[drop_reason::kInvalidScan], 360u);
  }
  // An empty bad scan still counts once.
  sensor_msgs::LaserScan empty = scanMsg();
  empty.ranges.clear();
  empty.angle_increment = kNanF;
  std::map<std::string, std::uint64_t> drops;
  EXPECT_TRUE(scanToReadings(empty, 10, 101.0, &drops).empty());
  EXPECT_EQ(drops[drop_reason::kInvalidScan], 1u);
}

TEST(SensorInput, ScanHeaderAcceptsDecreasingAndSingleBeamScans)
{
  sensor_msgs::LaserScan scan = scanMsg();
  std::swap(scan.angle_min, scan.angle_max);
  scan.angle_increment = -scan.angle_increment;
  EXPECT_EQ(scanHeaderProblem(scan), "");
  std::map<std::string, std::uint64_t> drops;
  const std::vector<TimedReading> readings = scanToReadings(scan, 2, 101.0, &drops);
  ASSERT_EQ(readings.size(), 2u);
  EXPECT_NEAR(core::angleDiff(readings[1].beam.theta, scan.angle_min + 180 * scan.angle_increment), 0.0, 1e-5);

  sensor_msgs::LaserScan single = scanMsg();
  single.angle_max = single.angle_min;
  single.ranges.assign(1, 2.0f);
  single.time_increment = 0.0f;
  single.scan_time = 0.0f;
  single.range_min = 0.0f;
  EXPECT_EQ(scanHeaderProblem(single), "");
  EXPECT_EQ(scanToReadings(single, 10, 101.0, &drops).size(), 1u);
}

}  // namespace
}  // namespace fdml_localization
