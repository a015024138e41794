// ReadingBuffer hardening (no ROS): readings from the future, bounded per-frame state, and frame
// ids with a leading '/'.
#include "fdml_localization/ros/reading_buffer.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fdml_localization
{
namespace
{
TimedReading readingAt(const std::string& frame, double stamp, double received)
{
  TimedReading r;
  r.frame_id = frame;
  r.stamp = std::llround(stamp * 1e9);
  r.range = 1.0;
  r.max_range = 5.0;
  r.received = received;
  return r;
}

/// Every frame but "base_link" and "front" is unknown; records the frames asked for.
struct StaticTf
{
  std::vector<std::string> asked;

  LookupStatus operator()(const std::string& frame, std::int64_t /*stamp*/, core::Pose2* pose)
  {
    asked.push_back(frame);
    if (frame == "base_link" || frame == "front")
    {
      *pose = core::Pose2(1.0, 2.0, 0.5);
      return LookupStatus::Ok;
    }
    return LookupStatus::UnknownFrame;
  }
};

ReadingBuffer::Options continuousOptions()
{
  ReadingBuffer::Options o;
  o.batch_size = 3;
  o.continuous = true;
  o.transform_tolerance = 0.1;
  return o;
}

TEST(ReadingBufferLimits, ReadingFromTheFutureIsDroppedAndDoesNotPoisonItsFrame)
{
  ReadingBuffer buffer(continuousOptions());
  std::string reason;
  EXPECT_TRUE(buffer.add(readingAt("front", 100.0, 100.0)));
  // One hour ahead of the clock: dropped as such.
  EXPECT_FALSE(buffer.add(readingAt("front", 3700.0, 100.1), &reason));
  EXPECT_EQ(reason, drop_reason::kFutureStamp);
  EXPECT_EQ(buffer.dropCounts().at(drop_reason::kFutureStamp), 1u);
  // The readings after it are accepted (they are not "backwards" from the future one).
  for (int i = 1; i <= 5; ++i)
  {
    EXPECT_TRUE(buffer.add(readingAt("front", 100.0 + 0.1 * i, 100.0 + 0.1 * i), &reason)) << i << ": " << reason;
  }
  // Within the tolerance (0.5 s by default) ahead is fine, and becomes the frame's newest stamp.
  EXPECT_TRUE(buffer.add(readingAt("front", 101.0, 100.6)));
  EXPECT_FALSE(buffer.add(readingAt("front", 100.9, 100.7), &reason));
  EXPECT_EQ(reason, drop_reason::kStampBackwards);
  EXPECT_EQ(buffer.dropped(), 2u);
  // Just beyond the tolerance is not.
  EXPECT_FALSE(buffer.add(readingAt("front", 102.0, 101.4), &reason));
  EXPECT_EQ(reason, drop_reason::kFutureStamp);

  // The tolerance is an option.
  ReadingBuffer::Options strict = continuousOptions();
  strict.future_tolerance = 0.0;
  ReadingBuffer strict_buffer(strict);
  EXPECT_FALSE(strict_buffer.add(readingAt("front", 100.001, 100.0)));
  EXPECT_TRUE(strict_buffer.add(readingAt("front", 100.0, 100.0)));
}

TEST(ReadingBufferLimits, ManyDistinctFramesKeepTheStateBounded)
{
  ReadingBuffer::Options options = continuousOptions();
  options.max_frames = 100;
  ReadingBuffer buffer(options);
  StaticTf tf;
  const int frames = 90000;
  double t = 10.0;
  for (int i = 0; i < frames; ++i)
  {
    t += 1e-3;
    ASSERT_TRUE(buffer.add(readingAt("frame_" + std::to_string(i), t, t))) << i;
    if (i % 50 == 0)
    {
      ASSERT_TRUE(buffer.add(readingAt("front", t, t)));  // a busy frame stays remembered
    }
    if (i % 1000 == 999)
    {
      buffer.resolve(t + 1.0, "base_link", std::ref(tf));  // the unknown frames time out
      tf.asked.clear();
    }
    ASSERT_LE(buffer.trackedFrames(), 100u);
  }
  EXPECT_EQ(buffer.trackedFrames(), 100u);
  EXPECT_EQ(buffer.framesEvicted(), static_cast<std::uint64_t>(frames + 1 - 100));
  EXPECT_LE(buffer.pendingCount(), 1000u);
  // The busy frame still has its newest stamp: an older reading is still refused.
  std::string reason;
  EXPECT_FALSE(buffer.add(readingAt("front", t - 1.0, t), &reason));
  EXPECT_EQ(reason, drop_reason::kStampBackwards);
  // An evicted frame's next reading is accepted as a first one.
  EXPECT_TRUE(buffer.add(readingAt("frame_0", 5.0, t)));
}

TEST(ReadingBufferLimits, LeadingSlashesAreStrippedAsTf2Expects)
{
  EXPECT_EQ(tf2FrameId("/front"), "front");
  EXPECT_EQ(tf2FrameId("//front"), "front");
  EXPECT_EQ(tf2FrameId("front/sub"), "front/sub");
  EXPECT_EQ(tf2FrameId("/"), "");

  ReadingBuffer buffer(continuousOptions());
  StaticTf tf;
  EXPECT_TRUE(buffer.add(readingAt("/front", 10.0, 10.0)));
  EXPECT_TRUE(buffer.add(readingAt("front", 10.1, 10.1)));
  std::string reason;
  EXPECT_FALSE(buffer.add(readingAt("//front", 10.05, 10.2), &reason));  // the same frame, backwards
  EXPECT_EQ(reason, drop_reason::kStampBackwards);
  EXPECT_FALSE(buffer.add(readingAt("/", 10.3, 10.3), &reason));
  EXPECT_EQ(reason, drop_reason::kEmptyFrameId);
  EXPECT_TRUE(buffer.resolve(10.3, "base_link", std::ref(tf)).empty());
  EXPECT_EQ(buffer.resolvedCount(), 2u);
  for (const std::string& frame : tf.asked)
  {
    EXPECT_NE(frame[0], '/') << frame;  // tf2 never sees a leading slash
  }
}

}  // namespace
}  // namespace fdml_localization
