// on_request mode over a simulated patrol (issue 17): one ~relocalize gives an answer that stays
// right while the robot drives on; an absurd timeout is refused; after a kidnap the track is
// reported lost and no pose is published for long; a wrong initialpose is refused, a right one
// brings the pose back.
#include "tracking_scorer.h"

#include <fdml_localization/Kidnap.h>
#include <fdml_localization/Relocalize.h>
#include <fdml_localization/Status.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <ros/ros.h>
#include <tf2/LinearMath/Quaternion.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <functional>
#include <mutex>
#include <string>

namespace
{
using fdml_test::Pose;
using fdml_test::Scorer;

/// Every ~status since the last forget(): one status may stand for a single batch (the node
/// publishes one per tracking update), so a poll of the newest alone can miss it.
class StatusRecorder
{
public:
  explicit StatusRecorder(ros::NodeHandle& nh)
    : sub_(nh.subscribe("fdml_localizer/status", 50, &StatusRecorder::onStatus, this))
  {}

  /// True when a status received since the last forget() satisfies @p predicate.
  bool seen(const std::function<bool(const fdml_localization::Status&)>& predicate)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return std::any_of(received_.begin(), received_.end(), predicate);
  }

  /// Forgets the statuses received so far: seen() looks at later ones only.
  void forget()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    received_.clear();
  }

private:
  void onStatus(const fdml_localization::Status& msg)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (received_.size() >= kMaxKept)
    {
      received_.pop_front();
    }
    received_.push_back(msg);
  }

  static constexpr std::size_t kMaxKept = 100000;
  std::mutex mutex_;
  std::deque<fdml_localization::Status> received_;
  ros::Subscriber sub_;
};

/// Waits (wall time, callbacks on the spinner) until @p predicate holds; false on timeout.
bool waitFor(const std::function<bool()>& predicate, double timeout)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end)
  {
    if (predicate())
    {
      return true;
    }
    ros::WallDuration(0.02).sleep();
  }
  return predicate();
}

geometry_msgs::PoseWithCovarianceStamped hint(double x, double y, double yaw, double sigma_xy, double sigma_yaw)
{
  geometry_msgs::PoseWithCovarianceStamped msg;
  msg.header.frame_id = "map";
  msg.header.stamp = ros::Time::now();
  msg.pose.pose.position.x = x;
  msg.pose.pose.position.y = y;
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, yaw);
  msg.pose.pose.orientation.x = q.x();
  msg.pose.pose.orientation.y = q.y();
  msg.pose.pose.orientation.z = q.z();
  msg.pose.pose.orientation.w = q.w();
  msg.pose.covariance[0] = msg.pose.covariance[7] = sigma_xy * sigma_xy;
  msg.pose.covariance[35] = sigma_yaw * sigma_yaw;
  return msg;
}

/// The nodes and clients of the test.
struct Fixture
{
  ros::NodeHandle nh;
  Scorer scorer{ nh };
  StatusRecorder status{ nh };
  ros::Publisher initialpose = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("initialpose", 2);
  ros::ServiceClient kidnap = nh.serviceClient<fdml_localization::Kidnap>("fdml_simulator/kidnap");
  ros::ServiceClient relocalize = nh.serviceClient<fdml_localization::Relocalize>("fdml_localizer/relocalize");

  Pose truthNow()
  {
    std::lock_guard<std::mutex> lock(scorer.mutex);
    return scorer.latest_truth;
  }
};

/// One ~relocalize: right, then right while the robot drives on for 30 s.
void relocalizeAndDrive(Fixture& f)
{
  fdml_localization::Relocalize srv;
  srv.request.timeout = 30.0;
  ASSERT_TRUE(f.relocalize.call(srv));
  ASSERT_TRUE(srv.response.success) << srv.response.message;
  ASSERT_TRUE(srv.response.result.unambiguous);
  double start = 0.0;
  {
    std::lock_guard<std::mutex> lock(f.scorer.mutex);
    Pose truth;
    ASSERT_TRUE(f.scorer.truthAt(srv.response.result.header.stamp, &truth));
    const auto& best = srv.response.result.candidates.at(0).pose;
    EXPECT_LT(std::hypot(best.position.x - truth.x, best.position.y - truth.y), 0.1) << srv.response.message;
    f.scorer.restartCounts();
    start = f.scorer.now;
  }
  ASSERT_TRUE(waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(f.scorer.mutex);
        return f.scorer.now > start + 30.0;
      },
      60.0));
  std::lock_guard<std::mutex> lock(f.scorer.mutex);
  const double right = static_cast<double>(f.scorer.right_after_fix) / std::max(1, f.scorer.samples_after_fix);
  ROS_INFO("on_request: after one ~relocalize, right %.1f %%, wrong %d of %d samples over 30 s", 100.0 * right,
           f.scorer.wrong_after_fix, f.scorer.samples_after_fix);
  EXPECT_GE(right, 0.9);
  EXPECT_LE(f.scorer.wrong_after_fix, f.scorer.samples_after_fix / 50);
}

/// A kidnap: the track is reported lost; a hint 5 m off is refused, one near the truth accepted.
void kidnapAndHints(Fixture& f)
{
  fdml_localization::Kidnap move;
  move.request.pose.x = 4.0;
  move.request.pose.y = 3.0;
  f.status.forget();
  ASSERT_TRUE(f.kidnap.call(move));
  ASSERT_TRUE(move.response.success) << move.response.message;
  EXPECT_TRUE(waitFor([&] { return f.status.seen([](const auto& s) { return s.state == s.LOST; }); }, 20.0));
  Pose truth = f.truthNow();
  f.status.forget();
  f.initialpose.publish(hint(truth.x + 4.0, truth.y + 3.0, truth.yaw, 0.1, 0.05));
  EXPECT_TRUE(waitFor(
      [&] { return f.status.seen([](const auto& s) { return s.message.find("initialpose refused") == 0; }); }, 20.0));
  truth = f.truthNow();
  f.status.forget();
  f.initialpose.publish(hint(truth.x + 0.15, truth.y - 0.1, truth.yaw + 0.1, 0.2, 0.1));
  EXPECT_TRUE(waitFor([&] { return f.status.seen([](const auto& s) { return s.state == s.TRACKING; }); }, 20.0));
  int right_before = 0;
  {
    std::lock_guard<std::mutex> lock(f.scorer.mutex);
    right_before = f.scorer.right;
  }
  EXPECT_TRUE(waitFor(
      [&] {
        std::lock_guard<std::mutex> lock(f.scorer.mutex);
        return f.scorer.right > right_before + 5;
      },
      20.0))
      << "the pose was not right again after the hint";
}
}  // namespace

TEST(TrackingRequests, RelocalizeThenTrackKidnapAndHints)
{
  Fixture f;
  ASSERT_TRUE(f.kidnap.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(f.relocalize.waitForExistence(ros::Duration(60.0)));
  fdml_localization::Relocalize absurd;
  absurd.request.timeout = 1e308;
  ASSERT_TRUE(f.relocalize.call(absurd));
  EXPECT_FALSE(absurd.response.success);
  EXPECT_NE(absurd.response.message.find("out of range"), std::string::npos) << absurd.response.message;
  relocalizeAndDrive(f);
  kidnapAndHints(f);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tracking_requests");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int status = RUN_ALL_TESTS();
  ros::shutdown();
  return status;
}
