// End-to-end kidnapped-robot test: simulator + localizer, eight kidnaps, ~relocalize after each.
#include <fdml_localization/Kidnap.h>
#include <fdml_localization/Relocalize.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2/LinearMath/Transform.h>
#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/transform_listener.h>

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
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
  explicit TruthHistory(ros::NodeHandle& nh) : sub_(nh.subscribe("ground_truth", 500, &TruthHistory::onOdom, this))
  {}

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

/// The map -> odom transforms on /tf, numbered in arrival order.
class MapToOdomRecorder
{
public:
  explicit MapToOdomRecorder(ros::NodeHandle& nh) : sub_(nh.subscribe("/tf", 100, &MapToOdomRecorder::onTf, this))
  {}

  std::uint64_t count()
  {
    std::lock_guard<std::mutex> lock(mutex_);
    return count_;
  }

  /// The newest map -> odom, when one arrived after the first @p after of them.
  bool latestAfter(std::uint64_t after, geometry_msgs::TransformStamped& out)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (count_ <= after)
    {
      return false;
    }
    out = latest_;
    return true;
  }

private:
  void onTf(const tf2_msgs::TFMessage& msg)
  {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const geometry_msgs::TransformStamped& t : msg.transforms)
    {
      if (t.header.frame_id == "map" && t.child_frame_id == "odom")
      {
        latest_ = t;
        ++count_;
      }
    }
  }

  std::mutex mutex_;
  std::uint64_t count_ = 0;
  geometry_msgs::TransformStamped latest_;
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
/// Checks that the map -> odom published after the answer numbered @p answered, composed with
/// odom -> base_link at @p stamp, is the true pose @p t.
void expectTfMatchesTruth(MapToOdomRecorder& map_odom, std::uint64_t answered, tf2_ros::Buffer& tf_buffer,
                          const ros::Time& stamp, const TruthSample& t, double pos_tol, double ang_tol)
{
  // The map -> odom the localizer publishes after this answer (future-dated, as AMCL does, so a
  // tf lookup between the old and the new one would interpolate between them) composed with
  // the simulator's odom -> base_link at the result's stamp is the true pose at that stamp.
  geometry_msgs::TransformStamped map_to_odom;
  ASSERT_TRUE(waitFor([&] { return map_odom.latestAfter(answered, map_to_odom); }, 10.0)) << "no map -> odom on tf "
                                                                                             "after the answer";
  std::string error;
  ASSERT_TRUE(tf_buffer.canTransform("odom", "base_link", stamp, ros::Duration(5.0), &error)) << error;
  const geometry_msgs::TransformStamped odom_to_base = tf_buffer.lookupTransform("odom", "base_link", stamp);
  tf2::Transform a, b;
  tf2::fromMsg(map_to_odom.transform, a);
  tf2::fromMsg(odom_to_base.transform, b);
  const tf2::Transform map_to_base = a * b;
  EXPECT_LE(std::hypot(map_to_base.getOrigin().x() - t.x, map_to_base.getOrigin().y() - t.y), pos_tol);
  EXPECT_LE(angleError(tf2::getYaw(map_to_base.getRotation()), t.yaw), ang_tol);
}

/// True when some candidate lies within the tolerances of the truth @p t.
bool truthAmong(const std::vector<fdml_localization::Candidate>& candidates, const TruthSample& t, double pos_tol,
                double ang_tol)
{
  for (const auto& candidate : candidates)
  {
    if (std::hypot(candidate.pose.position.x - t.x, candidate.pose.position.y - t.y) <= pos_tol &&
        angleError(tf2::getYaw(candidate.pose.orientation), t.yaw) <= ang_tol)
    {
      return true;
    }
  }
  return false;
}

}  // namespace

TEST(EndToEnd, KidnapsAreRelocalizedAndTfFollows)
{
  ros::NodeHandle nh;
  TruthHistory truth(nh);
  MapToOdomRecorder map_odom(nh);
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
  constexpr int kKidnaps = 8;
  for (int n = 0; n < kKidnaps; ++n)
  {
    fdml_localization::Kidnap move;
    move.request.random = true;
    ASSERT_TRUE(kidnap.call(move));
    ASSERT_TRUE(move.response.success) << move.response.message;

    fdml_localization::Relocalize srv;
    srv.request.timeout = 60.0;
    ASSERT_TRUE(relocalize.call(srv));
    const std::uint64_t answered = map_odom.count();
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
    // A symmetric place may leave the answer ambiguous: then the truth must be among the
    // candidates (and no pose is claimed); an unambiguous answer must be right.
    const bool truth_among = truthAmong(result.candidates, t, pos_tol, ang_tol);
    const bool unambiguous = result.unambiguous;
    EXPECT_TRUE(ok || !unambiguous) << "kidnap " << n << ": an unambiguous answer is wrong";
    good += (unambiguous ? ok : truth_among) ? 1 : 0;
    ROS_INFO("kidnap %d: truth (%.3f, %.3f, %.3f), error %.1f cm %.2f deg, %zu candidates, truth among them: %d: %s", n,
             t.x, t.y, t.yaw, 100.0 * err_pos, err_ang * 180.0 / M_PI, result.candidates.size(), truth_among,
             srv.response.message.c_str());
    if (ok && unambiguous)
    {
      expectTfMatchesTruth(map_odom, answered, tf_buffer, result.header.stamp, t, pos_tol, ang_tol);
      ++tf_checked;
    }
  }
  EXPECT_GE(good, kKidnaps - 1) << "relocalized within 5 cm and 2 degrees (best unambiguous, or truth among "
                                   "ambiguous candidates) in "
                                << good << " of " << kKidnaps << " kidnaps";
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
