// Cone readings through the ROS conversions (issue 18): Reading.field_of_view and
// Range.field_of_view become core::Reading::half_angle = field_of_view / 2; a bad value is a
// conversion error naming the field (Reading) or a drop with its own reason (Range); LaserScan
// beams stay rays.
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/sensor_input.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace core = fdml_localization::core;
namespace fl = fdml_localization;

namespace
{
const double kNan = std::numeric_limits<double>::quiet_NaN();

fl::Reading readingMsg(double field_of_view)
{
  fl::Reading msg;
  msg.range = 2.0;
  msg.max_range = 4.0;
  msg.field_of_view = field_of_view;
  return msg;
}

sensor_msgs::Range rangeMsg(float field_of_view)
{
  sensor_msgs::Range msg;
  msg.header.frame_id = "tof";
  msg.header.stamp = ros::Time(3.0);
  msg.min_range = 0.05f;
  msg.max_range = 4.0f;
  msg.range = 1.5f;
  msg.field_of_view = field_of_view;
  return msg;
}
}  // namespace

TEST(ReadingFieldOfView, MessageCarriesTheHalfAngle)
{
  EXPECT_EQ(fl::fromReadingMsg(readingMsg(0.0)).half_angle, 0.0);  // old clients: a ray
  EXPECT_DOUBLE_EQ(fl::fromReadingMsg(readingMsg(0.47)).half_angle, 0.235);
  EXPECT_EQ(fl::fromReadingMsg(readingMsg(core::kPi)).half_angle, core::kMaxConeHalfAngle);
  core::Reading reading;
  reading.range = 1.0;
  reading.max_range = 2.0;
  reading.half_angle = 0.2;
  EXPECT_DOUBLE_EQ(fl::toReadingMsg(reading).field_of_view, 0.4);
  EXPECT_EQ(fl::fromReadingMsg(fl::toReadingMsg(reading)).half_angle, 0.2);
}

TEST(ReadingFieldOfView, BadValuesAreErrorsNamingTheField)
{
  for (const double bad : { kNan, -0.1, 3.2, std::numeric_limits<double>::infinity() })
  {
    EXPECT_THROW(fl::fromReadingMsg(readingMsg(bad)), std::invalid_argument) << bad;
    std::vector<fl::Reading> msgs(3, readingMsg(0.1));
    msgs[2] = readingMsg(bad);
    try
    {
      fl::fromReadingMsgs(msgs);
      ADD_FAILURE() << "no error for " << bad;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_EQ(std::string(e.what()).rfind("readings[2].field_of_view: ", 0), 0u) << e.what();
    }
  }
}

TEST(ReadingFieldOfView, RangeGivesTheHalfAngleAndDropsBadValues)
{
  fl::TimedReading reading;
  std::string reason;
  ASSERT_TRUE(fl::rangeToReading(rangeMsg(0.0f), 3.0, &reading, &reason));
  EXPECT_EQ(reading.half_angle, 0.0);
  ASSERT_TRUE(fl::rangeToReading(rangeMsg(0.47f), 3.0, &reading, &reason));
  EXPECT_DOUBLE_EQ(reading.half_angle, 0.5 * static_cast<double>(0.47f));
  // A float32 pi rounds above pi: still the half-plane.
  ASSERT_TRUE(fl::rangeToReading(rangeMsg(static_cast<float>(core::kPi)), 3.0, &reading, &reason));
  EXPECT_EQ(reading.half_angle, core::kMaxConeHalfAngle);
  for (const float bad : { std::numeric_limits<float>::quiet_NaN(), -0.01f, 3.5f })
  {
    reason.clear();
    EXPECT_FALSE(fl::rangeToReading(rangeMsg(bad), 3.0, &reading, &reason)) << bad;
    EXPECT_EQ(reason, fl::drop_reason::kInvalidFieldOfView);
  }
}

TEST(ReadingFieldOfView, ScanBeamsStayRays)
{
  sensor_msgs::LaserScan scan;
  scan.header.frame_id = "laser";
  scan.header.stamp = ros::Time(10.0);
  scan.angle_min = 0.0f;
  scan.angle_increment = 0.1f;
  scan.range_min = 0.1f;
  scan.range_max = 10.0f;
  scan.ranges.assign(20, 3.0f);
  std::map<std::string, std::uint64_t> drops;
  const std::vector<fl::TimedReading> beams = fl::scanToReadings(scan, 5, 11.0, &drops);
  ASSERT_EQ(beams.size(), 5u);
  for (const fl::TimedReading& beam : beams)
  {
    EXPECT_EQ(beam.half_angle, 0.0);
  }
}

TEST(ReadingFieldOfView, TheBatchCarriesEachHalfAngle)
{
  std::vector<fl::ResolvedReading> resolved(3);
  for (std::size_t i = 0; i < resolved.size(); ++i)
  {
    resolved[i].raw.stamp = static_cast<std::int64_t>(i + 1);
    resolved[i].raw.range = 1.0;
    resolved[i].raw.max_range = 4.0;
    resolved[i].raw.half_angle = 0.1 * static_cast<double>(i);
  }
  const fl::Batch batch = fl::makeBatch(resolved);
  ASSERT_EQ(batch.readings.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i)
  {
    EXPECT_EQ(batch.readings[i].half_angle, 0.1 * static_cast<double>(i));
  }
}
