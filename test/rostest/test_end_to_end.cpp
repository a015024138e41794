// End-to-end kidnapped-robot test: simulator + localizer, five kidnaps, ~relocalize after each.
#include <fdml_localization/Kidnap.h>
#include <fdml_localization/Relocalize.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2/utils.h>
#include <tf2_ros/transform_listener.h>

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <mutex>

namespace
{
struct TruthSample
{
  ros::Time stamp;
  double x, y, yaw;
};

/// Ground-truth poses by stamp, interpolated at any recent time.
class TruthHistory
{
public:
  explicit TruthHistory(ros::NodeHandle& nh) : sub_(nh.subscribe("ground_truth", 500, &TruthHistory::onOdom, this)) {}

  bool at(const ros::Time& stamp, TruthSample& out)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (samples_.size() < 2 || stamp < samples_.front().stamp || stamp > samples_.back().stamp)
    {
      return false;
    }
    for (std::size_t i = 1; i < samples_.size(); ++i)
    {
      if (samples_[i].stamp >= stamp)
      {
        const TruthSample& a = samples_[i - 1];
        const TruthSample& b = samples_[i];
        const double span = (b.stamp - a.stamp).toSec();
        const double w = span > 0.0 ? (stamp - a.stamp).toSec() / span : 0.0;
        out = { stamp, a.x + w * (b.x - a.x), a.y + w * (b.y - a.y),
                a.yaw + w * std::remainder(b.yaw - a.yaw, 2.0 * M_PI) };
        return true;
      }
    }
    return false;
  }

private:
  void onOdom(const nav_msgs::Odometry& msg)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    samples_.push_back({ msg.header.stamp, msg.pose.pose.position.x, msg.pose.pose.position.y,
                         tf2::getYaw(msg.pose.pose.orientation) });
    while (samples_.size() > 3000)
    {
      samples_.pop_front();
    }
  }

  std::mutex mutex_;
  std::deque<TruthSample> samples_;
  ros::Subscriber sub_;
};

double angleError(double a, double b)
{
  return std::abs(std::remainder(a - b, 2.0 * M_PI));
}

/// Waits (in ROS time, with callbacks serviced by the spinner) until @p pred holds or timeout.
template <typename Pred>
bool waitFor(Pred pred, double timeout)
{
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(timeout);
  while (ros::ok() && ros::WallTime::now() < end)
  {
    if (pred())
    {
      return true;
    }
    ros::WallDuration(0.01).sleep();
  }
  return pred();
}
}  // namespace

TEST(EndToEnd, KidnapsAreRelocalizedAndTfFollows)
{
  ros::NodeHandle nh;
  TruthHistory truth(nh);
  tf2_ros::Buffer tf_buffer(ros::Duration(30.0));
  tf2_ros::TransformListener tf_listener(tf_buffer);
  ros::ServiceClient kidnap = nh.serviceClient<fdml_localization::Kidnap>("fdml_simulator/kidnap");
  ros::ServiceClient relocalize = nh.serviceClient<fdml_localization::Relocalize>("fdml_localizer/relocalize");
  ASSERT_TRUE(kidnap.waitForExistence(ros::Duration(60.0)));
  ASSERT_TRUE(relocalize.waitForExistence(ros::Duration(60.0)));

  const double pos_tol = 0.05;
  const double ang_tol = 2.0 * M_PI / 180.0;
  int good = 0;
  int tf_checked = 0;
  for (int n = 0; n < 5; ++n)
  {
    fdml_localization::Kidnap move;
    move.request.random = true;
    ASSERT_TRUE(kidnap.call(move));
    ASSERT_TRUE(move.response.success) << move.response.message;

    fdml_localization::Relocalize srv;
    srv.request.timeout = 60.0;
    ASSERT_TRUE(relocalize.call(srv));
    const auto& result = srv.response.result;
    if (!srv.response.success || result.candidates.empty())
    {
      ADD_FAILURE() << "kidnap " << n << ": " << srv.response.message;
      continue;
    }
    TruthSample t;
    ASSERT_TRUE(waitFor([&] { return truth.at(result.header.stamp, t); }, 10.0)) << "no ground truth at the stamp";
    const auto& best = result.candidates.front().pose;
    const double err_pos = std::hypot(best.position.x - t.x, best.position.y - t.y);
    const double err_ang = angleError(tf2::getYaw(best.orientation), t.yaw);
    const bool ok = err_pos <= pos_tol && err_ang <= ang_tol;
    good += ok ? 1 : 0;
    ROS_INFO("kidnap %d: truth (%.3f, %.3f, %.3f), error %.1f cm %.2f deg, %zu candidates: %s", n, t.x, t.y, t.yaw,
             100.0 * err_pos, err_ang * 180.0 / M_PI, result.candidates.size(), srv.response.message.c_str());

    const bool unambiguous = result.candidates.size() == 1 || result.candidates[0].inliers > result.candidates[1].inliers;
    if (ok && unambiguous)
    {
      // map -> odom (localizer) and odom -> base_link (simulator) compose to the true pose.
      std::string error;
      ASSERT_TRUE(tf_buffer.canTransform("map", "base_link", result.header.stamp, ros::Duration(10.0), &error))
          << error;
      const geometry_msgs::TransformStamped tf =
          tf_buffer.lookupTransform("map", "base_link", result.header.stamp);
      EXPECT_LE(std::hypot(tf.transform.translation.x - t.x, tf.transform.translation.y - t.y), pos_tol);
      EXPECT_LE(angleError(tf2::getYaw(tf.transform.rotation), t.yaw), ang_tol);
      ++tf_checked;
    }
  }
  EXPECT_GE(good, 4) << "relocalized within 5 cm and 2 degrees in " << good << " of 5 kidnaps";
  EXPECT_GE(tf_checked, 3) << "map -> base_link was checked after only " << tf_checked << " kidnaps";
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_end_to_end");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int status = RUN_ALL_TESTS();
  ros::shutdown();
  return status;
}
