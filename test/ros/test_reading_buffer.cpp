// ReadingBuffer: batching, g_i from a lookup table, modes and drop accounting (no ROS).
#include "fdml_localization/ros/reading_buffer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

namespace fdml_localization
{
namespace
{
std::int64_t nanoseconds(double seconds)
{
  return std::llround(seconds * 1e9);
}

double seconds(std::int64_t nanoseconds)
{
  return static_cast<double>(nanoseconds) * 1e-9;
}

/// A robot turning and driving in odom: base(t) = (1 + 0.2 t, 2 - 0.1 t, 0.5 + 0.8 t).
core::Pose2 basePose(double t)
{
  return core::Pose2(1.0 + 0.2 * t, 2.0 - 0.1 * t, core::wrapAngle(0.5 + 0.8 * t));
}

/// Sensor "front" mounted at (0.2, 0.05, 0.3) on the base; "back" at (-0.1, 0, pi).
core::Pose2 mounting(const std::string& frame)
{
  return frame == "front" ? core::Pose2(0.2, 0.05, 0.3) : core::Pose2(-0.1, 0.0, core::kPi);
}

/// Poses in odom: known frames "base_link", "front", "back"; "late" becomes available after
/// available_after; anything else is unknown.
struct FakeTf
{
  double now = 0.0;
  double available_after = 1e9;
  int calls = 0;

  LookupStatus operator()(const std::string& frame, std::int64_t stamp_ns, core::Pose2* pose)
  {
    ++calls;
    const double stamp = seconds(stamp_ns);
    if (frame == "base_link")
    {
      *pose = basePose(stamp);
      return LookupStatus::Ok;
    }
    if (frame == "front" || frame == "back")
    {
      *pose = core::compose(basePose(stamp), mounting(frame));
      return LookupStatus::Ok;
    }
    if (frame == "late")
    {
      if (now < available_after)
      {
        return LookupStatus::NotYet;
      }
      *pose = core::compose(basePose(stamp), mounting("front"));
      return LookupStatus::Ok;
    }
    return LookupStatus::UnknownFrame;
  }
};

TimedReading reading(const std::string& frame, double stamp, double range = 1.0)
{
  TimedReading r;
  r.frame_id = frame;
  r.stamp = nanoseconds(stamp);
  r.range = range;
  r.max_range = 5.0;
  r.received = stamp;
  return r;
}

ReadingBuffer::Options options(int k, int stride, bool continuous)
{
  ReadingBuffer::Options o;
  o.batch_size = k;
  o.stride = stride;
  o.continuous = continuous;
  o.transform_tolerance = 0.2;
  return o;
}

/// Independent g_i: the sensor pose at t_i relative to the base at t_1, by explicit trigonometry.
core::Pose2 expectedOffset(double t1, double ti, const core::Pose2& sensor_mount, const core::Pose2& beam)
{
  const core::Pose2 b1 = basePose(t1);
  const core::Pose2 bi = basePose(ti);
  // Sensor (beam) pose in odom at ti.
  const double mx = sensor_mount.x + std::cos(sensor_mount.theta) * beam.x - std::sin(sensor_mount.theta) * beam.y;
  const double my = sensor_mount.y + std::sin(sensor_mount.theta) * beam.x + std::cos(sensor_mount.theta) * beam.y;
  const double sx = bi.x + std::cos(bi.theta) * mx - std::sin(bi.theta) * my;
  const double sy = bi.y + std::sin(bi.theta) * mx + std::cos(bi.theta) * my;
  const double st = bi.theta + sensor_mount.theta + beam.theta;
  // Expressed in the base frame at t1.
  const double dx = sx - b1.x;
  const double dy = sy - b1.y;
  return core::Pose2(std::cos(b1.theta) * dx + std::sin(b1.theta) * dy,
                     -std::sin(b1.theta) * dx + std::cos(b1.theta) * dy, core::wrapAngle(st - b1.theta));
}

void expectPoseNear(const core::Pose2& a, const core::Pose2& b)
{
  EXPECT_NEAR(a.x, b.x, 1e-9);
  EXPECT_NEAR(a.y, b.y, 1e-9);
  EXPECT_NEAR(core::angleDiff(a.theta, b.theta), 0.0, 1e-9);
}

TEST(ReadingBuffer, BatchOffsetsComeFromOdometryAndMountingAtEachStamp)
{
  ReadingBuffer buffer(options(4, 4, true));
  FakeTf tf;
  const double stamps[4] = { 1.0, 1.3, 1.7, 2.2 };
  const char* frames[4] = { "front", "back", "front", "back" };
  for (int i = 0; i < 4; ++i)
  {
    TimedReading r = reading(frames[i], stamps[i], 1.0 + i);
    if (i == 2)
    {
      r.beam = core::Pose2(0.0, 0.0, -0.4);  // a LaserScan beam
    }
    EXPECT_TRUE(buffer.add(r));
  }
  tf.now = 2.2;
  EXPECT_TRUE(buffer.resolve(tf.now, "base_link", std::ref(tf)).empty());
  Batch batch;
  ASSERT_TRUE(buffer.takeBatch(&batch));
  ASSERT_EQ(batch.readings.size(), 4u);
  EXPECT_EQ(batch.first_stamp, nanoseconds(1.0));
  EXPECT_EQ(batch.newest_stamp, nanoseconds(2.2));
  expectPoseNear(batch.base_first, basePose(1.0));
  expectPoseNear(batch.base_newest, basePose(2.2));
  for (int i = 0; i < 4; ++i)
  {
    const core::Pose2 beam = i == 2 ? core::Pose2(0.0, 0.0, -0.4) : core::Pose2();
    expectPoseNear(batch.readings[static_cast<std::size_t>(i)].offset,
                   expectedOffset(1.0, stamps[i], mounting(frames[i]), beam));
    EXPECT_EQ(batch.readings[static_cast<std::size_t>(i)].range, 1.0 + i);
    EXPECT_EQ(batch.readings[static_cast<std::size_t>(i)].max_range, 5.0);
  }
  // The first reading's offset is its mounting: the base has not moved yet.
  expectPoseNear(batch.readings[0].offset, mounting("front"));
  EXPECT_FALSE(buffer.takeBatch(&batch));
}

TEST(ReadingBuffer, ContinuousModeSlidesByTheStride)
{
  ReadingBuffer buffer(options(3, 2, true));
  FakeTf tf;
  for (int i = 1; i <= 7; ++i)
  {
    buffer.add(reading("front", i * 0.1));
  }
  buffer.resolve(1.0, "base_link", std::ref(tf));
  std::vector<double> firsts;
  Batch batch;
  while (buffer.takeBatch(&batch))
  {
    firsts.push_back(seconds(batch.first_stamp));
    EXPECT_EQ(batch.readings.size(), 3u);
  }
  // Windows [1..3], [3..5], [5..7].
  ASSERT_EQ(firsts.size(), 3u);
  EXPECT_NEAR(firsts[0], 0.1, 1e-12);
  EXPECT_NEAR(firsts[1], 0.3, 1e-12);
  EXPECT_NEAR(firsts[2], 0.5, 1e-12);
  EXPECT_EQ(buffer.resolvedCount(), 1u);
}

TEST(ReadingBuffer, OnRequestModeSolvesOnceOnFreshReadings)
{
  ReadingBuffer buffer(options(3, 1, false));
  FakeTf tf;
  for (int i = 1; i <= 5; ++i)
  {
    buffer.add(reading("front", i * 0.1));
  }
  buffer.resolve(1.0, "base_link", std::ref(tf));
  Batch batch;
  EXPECT_FALSE(buffer.takeBatch(&batch));  // no request yet
  EXPECT_EQ(buffer.resolvedCount(), 3u);   // idle: only the newest k kept
  buffer.requestBatch();
  EXPECT_TRUE(buffer.batchRequested());
  EXPECT_EQ(buffer.resolvedCount(), 0u);  // old readings are not used
  for (int i = 6; i <= 9; ++i)
  {
    buffer.add(reading("front", i * 0.1));
  }
  buffer.resolve(1.0, "base_link", std::ref(tf));
  ASSERT_TRUE(buffer.takeBatch(&batch));
  EXPECT_NEAR(seconds(batch.first_stamp), 0.6, 1e-12);
  EXPECT_NEAR(seconds(batch.newest_stamp), 0.8, 1e-12);
  EXPECT_FALSE(buffer.batchRequested());
  EXPECT_FALSE(buffer.takeBatch(&batch));  // one batch per request
  EXPECT_EQ(buffer.dropped(), 0u);
}

TEST(ReadingBuffer, MalformedReadingsAreDroppedAndCountedByReason)
{
  ReadingBuffer buffer(options(3, 1, true));
  std::string reason;
  EXPECT_TRUE(buffer.add(reading("front", 5.0)));
  EXPECT_FALSE(buffer.add(reading("front", 4.0), &reason));  // backwards in its frame
  EXPECT_EQ(reason, drop_reason::kStampBackwards);
  EXPECT_TRUE(buffer.add(reading("front", 5.0)));  // equal stamps are fine
  EXPECT_TRUE(buffer.add(reading("back", 4.0)));   // other frames are independent
  EXPECT_FALSE(buffer.add(reading("", 6.0), &reason));
  EXPECT_EQ(reason, drop_reason::kEmptyFrameId);
  EXPECT_FALSE(buffer.add(reading("front", 0.0), &reason));
  EXPECT_EQ(reason, drop_reason::kZeroStamp);
  buffer.countDrop(drop_reason::kNanRange, 2);
  EXPECT_EQ(buffer.dropped(), 5u);
  EXPECT_EQ(buffer.dropCounts().at(drop_reason::kStampBackwards), 1u);
  EXPECT_EQ(buffer.dropCounts().at(drop_reason::kEmptyFrameId), 1u);
  EXPECT_EQ(buffer.dropCounts().at(drop_reason::kZeroStamp), 1u);
  EXPECT_EQ(buffer.dropCounts().at(drop_reason::kNanRange), 2u);
  EXPECT_EQ(buffer.pendingCount(), 3u);
}

TEST(ReadingBuffer, ReadingsWaitForTransformsUpToTheTolerance)
{
  ReadingBuffer buffer(options(3, 1, true));
  FakeTf tf;
  tf.available_after = 10.1;
  buffer.add(reading("late", 10.0));
  buffer.add(reading("ghost", 10.0));
  buffer.add(reading("front", 10.0));

  tf.now = 10.05;
  EXPECT_TRUE(buffer.resolve(tf.now, "base_link", std::ref(tf)).empty());
  EXPECT_EQ(buffer.pendingCount(), 2u);  // "late" and "ghost" wait; "front" is ready
  EXPECT_EQ(buffer.resolvedCount(), 1u);

  tf.now = 10.15;  // "late" is available now, within the 0.2 s tolerance
  EXPECT_TRUE(buffer.resolve(tf.now, "base_link", std::ref(tf)).empty());
  EXPECT_EQ(buffer.resolvedCount(), 2u);

  tf.now = 10.25;  // "ghost" has waited too long
  const auto dropped = buffer.resolve(tf.now, "base_link", std::ref(tf));
  ASSERT_EQ(dropped.size(), 1u);
  EXPECT_EQ(dropped[0].first.frame_id, "ghost");
  EXPECT_EQ(dropped[0].second, drop_reason::kUnknownFrame);
  EXPECT_EQ(buffer.pendingCount(), 0u);
  EXPECT_EQ(buffer.dropCounts().at(drop_reason::kUnknownFrame), 1u);

  // A known frame whose transform never comes is "transform_unavailable".
  tf.available_after = 1e9;
  buffer.add(reading("late", 11.0));
  tf.now = 11.5;
  const auto dropped2 = buffer.resolve(tf.now, "base_link", std::ref(tf));
  ASSERT_EQ(dropped2.size(), 1u);
  EXPECT_EQ(dropped2[0].second, drop_reason::kTransformUnavailable);
}

TEST(ReadingBuffer, OverflowIsCounted)
{
  ReadingBuffer::Options o = options(3, 1, true);
  o.max_pending = 2;
  ReadingBuffer buffer(o);
  std::string reason;
  EXPECT_TRUE(buffer.add(reading("front", 1.0)));
  EXPECT_TRUE(buffer.add(reading("front", 1.1)));
  EXPECT_FALSE(buffer.add(reading("front", 1.2), &reason));
  EXPECT_EQ(reason, drop_reason::kBufferOverflow);
}

TEST(ReadingBuffer, ClearKeepsCountersAndStampHistory)
{
  ReadingBuffer buffer(options(3, 1, true));
  buffer.countReceived(4);
  buffer.add(reading("front", 2.0));
  buffer.add(reading("front", 1.0));
  buffer.clear();
  EXPECT_EQ(buffer.pendingCount(), 0u);
  EXPECT_EQ(buffer.received(), 4u);
  EXPECT_EQ(buffer.dropped(), 1u);
  EXPECT_FALSE(buffer.add(reading("front", 1.5)));
}

}  // namespace
}  // namespace fdml_localization
