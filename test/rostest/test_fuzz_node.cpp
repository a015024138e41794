// Fuzz rostest of the fdml_localizer node (issue 15): a fixed seed, a few thousand malformed
// and odd Range and LaserScan messages (NaN and inf in every field, stamps from the future and
// the past, empty, unknown and slash-prefixed frames, hundreds of distinct frames), then
// ~localize and ~relocalize requests with bad fields. Asserts that the node stays up, that its
// diagnostics count every bad message under the right reason, that its per-frame state stays
// capped, and that afterwards it still relocalizes correctly on good readings.
#include "fuzz_messages.h"
#include "message_collector.h"
#include "node_test_scene.h"

#include "fdml_localization/ros/conversions.h"

#include <diagnostic_msgs/DiagnosticArray.h>
#include <fdml_localization/Localize.h>
#include <fdml_localization/Relocalize.h>
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <future>
#include <limits>
#include <sstream>

namespace fdml_localization
{
namespace test
{
namespace
{
constexpr std::uint32_t kSeed = 15;
constexpr int kRangeMessages = 3000;
constexpr int kBeamsPerScan = 10;          // fuzz_node.test's ~beams_per_scan
constexpr std::uint64_t kMaxFrames = 100;  // fuzz_node.test's ~max_sensor_frames
constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

/// The value of @p key in the node's diagnostics status, -1 when absent.
long long valueOf(const diagnostic_msgs::DiagnosticStatus& status, const std::string& key)
{
  for (const auto& kv : status.values)
  {
    if (kv.key == key)
    {
      return std::stoll(kv.value);
    }
  }
  return -1;
}

/// Compares the node's counters with the expectation; "" when they match, else what differs.
std::string mismatch(const diagnostic_msgs::DiagnosticStatus& status, const FuzzExpectation& expected)
{
  std::ostringstream out;
  if (valueOf(status, "readings received") != static_cast<long long>(expected.received))
  {
    out << "received " << valueOf(status, "readings received") << " of " << expected.received << "; ";
  }
  long long other = 0;  // drops under reasons the fuzzer does not expect (a field-of-view check)
  for (const auto& kv : status.values)
  {
    const std::string prefix = "dropped: ";
    if (kv.key.rfind(prefix, 0) == 0 && expected.drops.count(kv.key.substr(prefix.size())) == 0)
    {
      other += std::stoll(kv.value);
    }
  }
  for (const auto& drop : expected.drops)
  {
    long long want = static_cast<long long>(drop.second);
    long long got = valueOf(status, "dropped: " + drop.first);
    if (drop.first == "unknown_frame")
    {
      // Readings with a broken field of view: unknown_frame, or dropped for their field of view.
      want += static_cast<long long>(expected.odd_field_of_view);
      got += other;
    }
    if (got != want)
    {
      out << drop.first << " " << got << " (want " << want << "); ";
    }
  }
  return out.str();
}

/// Waits until the node's diagnostics match @p expected; "" on success, else the last mismatch.
std::string waitForCounters(Collector<diagnostic_msgs::DiagnosticArray>& diagnostics, const FuzzExpectation& expected,
                            diagnostic_msgs::DiagnosticStatus* matched)
{
  std::string last = "no diagnostics of the node";
  const bool ok = diagnostics.waitFor(
      [&](const diagnostic_msgs::DiagnosticArray& msg) {
        for (const auto& status : msg.status)
        {
          if (valueOf(status, "readings received") < 0)
          {
            continue;
          }
          last = mismatch(status, expected);
          if (last.empty())
          {
            *matched = status;
            return true;
          }
        }
        return false;
      },
      60.0);
  return ok ? std::string() : last;
}

fdml_localization::Reading readingMsg(double x, double y, double theta, double range, double max_range)
{
  fdml_localization::Reading reading;
  reading.sensor_offset.x = x;
  reading.sensor_offset.y = y;
  reading.sensor_offset.theta = theta;
  reading.range = range;
  reading.max_range = max_range;
  return reading;
}

/// ~localize requests with bad fields: each answered (success or a message), none fatal.
void fuzzLocalize(ros::NodeHandle& nh, std::mt19937& rng)
{
  ros::ServiceClient client = nh.serviceClient<fdml_localization::Localize>("fdml_localizer/localize");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(60.0)));
  const double bad[] = { kNan, kInf, -kInf, -1.0, 0.0, 1e4, -1e4, 1e-300 };
  std::uniform_int_distribution<int> pick(0, 7);
  for (int trial = 0; trial < 24; ++trial)
  {
    fdml_localization::Localize srv;
    const int k = trial % 8 == 0 ? trial / 8 : std::uniform_int_distribution<int>(3, trial % 8 == 1 ? 300 : 12)(rng);
    for (int i = 0; i < k; ++i)
    {
      srv.request.readings.push_back(readingMsg(0.0, 0.0, 0.6 * i, 1.0 + 0.1 * i, 8.0));
      double* fields[] = { &srv.request.readings.back().sensor_offset.x, &srv.request.readings.back().sensor_offset.y,
                           &srv.request.readings.back().sensor_offset.theta, &srv.request.readings.back().range,
                           &srv.request.readings.back().max_range };
      if (i % 3 == 0)
      {
        *fields[pick(rng) % 5] = bad[pick(rng)];
      }
    }
    ASSERT_TRUE(client.call(srv)) << "trial " << trial << ": the node did not answer ~localize";
    EXPECT_TRUE(srv.response.success || !srv.response.message.empty()) << "trial " << trial;
  }
}

/// ~relocalize requests with bad timeouts: each answered, none fatal (no readings: they time out).
void fuzzRelocalize(ros::NodeHandle& nh)
{
  ros::ServiceClient client = nh.serviceClient<fdml_localization::Relocalize>("fdml_localizer/relocalize");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(60.0)));
  for (double timeout : { kNan, -1.0, -kInf, kInf, 1e-300, 0.05 })
  {
    fdml_localization::Relocalize srv;
    srv.request.timeout = timeout;
    ASSERT_TRUE(client.call(srv)) << "timeout " << timeout << ": the node did not answer ~relocalize";
    EXPECT_FALSE(srv.response.success) << "timeout " << timeout << ": solved without readings";
    EXPECT_FALSE(srv.response.message.empty()) << "timeout " << timeout;
  }
}

/// A good relocalization: the robot turns in place while ~relocalize waits for its readings.
void expectGoodRelocalization(ros::NodeHandle& nh)
{
  TurningScene scene;
  ScenePublisher publisher(nh, scene);
  ASSERT_TRUE(publisher.waitForSubscribers(1, 30.0));
  ros::ServiceClient client = nh.serviceClient<fdml_localization::Relocalize>("fdml_localizer/relocalize");
  auto call = std::async(std::launch::async, [&client]() {
    fdml_localization::Relocalize srv;
    srv.request.timeout = 60.0;
    const bool ok = client.call(srv);
    return std::make_pair(ok, srv.response);
  });
  int next = 0;
  while (call.wait_for(std::chrono::milliseconds(50)) != std::future_status::ready && next < 2000)
  {
    publisher.publishReading(next++);
  }
  const auto outcome = call.get();
  ASSERT_TRUE(outcome.first);
  const auto& response = outcome.second;
  ASSERT_TRUE(response.success) << response.message;
  ASSERT_FALSE(response.result.candidates.empty());
  const int last = publisher.indexOf(response.result.header.stamp);
  ASSERT_GE(last, 0);
  const core::Pose2 best = fromPoseMsg(response.result.candidates.front().pose);
  const core::Pose2 truth = scene.baseInMap(last);
  EXPECT_LT((best.position() - truth.position()).norm(), 0.05);
  EXPECT_LT(std::fabs(core::angleDiff(best.theta, truth.theta)), 2.0 * core::kPi / 180.0);
}

TEST(LocalizerFuzz, BadMessagesAreCountedAndTheNodeStillRelocalizes)
{
  ros::NodeHandle nh;
  Collector<diagnostic_msgs::DiagnosticArray> diagnostics(nh, "/diagnostics");
  MessageFuzzer fuzzer(nh, kSeed, kBeamsPerScan);
  ASSERT_TRUE(fuzzer.waitForSubscribers(60.0));
  // About 500 messages a second: well within the node's subscriber queues.
  ros::WallRate rate(500.0);
  for (int i = 0; i < kRangeMessages; ++i)
  {
    fuzzer.publishRange();
    if (i % 10 == 0)
    {
      fuzzer.publishScan();
    }
    rate.sleep();
  }
  const FuzzExpectation& expected = fuzzer.expected();
  ASSERT_GT(expected.distinct_frames, 5 * kMaxFrames);

  diagnostic_msgs::DiagnosticStatus status;
  const std::string problem = waitForCounters(diagnostics, expected, &status);
  ASSERT_TRUE(problem.empty()) << problem;
  EXPECT_LE(valueOf(status, "sensor frames tracked"), static_cast<long long>(kMaxFrames));
  EXPECT_GT(valueOf(status, "sensor frames evicted"), 0);

  std::mt19937 rng(kSeed);
  fuzzLocalize(nh, rng);
  fuzzRelocalize(nh);
  expectGoodRelocalization(nh);
}

}  // namespace
}  // namespace test
}  // namespace fdml_localization

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_localizer_fuzz");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int result = RUN_ALL_TESTS();
  spinner.stop();
  return result;
}
