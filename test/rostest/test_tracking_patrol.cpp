// A whole simulated patrol scored against the ground truth (issue 17): every 0.1 s of simulated
// time the published map -> odom (while it is current: stamped at or after that time, as the
// localizer future-dates it) composed with the odometry is right (10 cm, 5 deg), wrong, or
// absent. The robot is kidnapped at ~kidnap_time. Asserts the fractions, the time to the first
// fix and the time to recover from the kidnap (limits are the test node's private parameters).
#include <fdml_localization/Kidnap.h>
#include <fdml_localization/Status.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2/utils.h>
#include <tf2_msgs/TFMessage.h>

#include <gtest/gtest.h>

#include <cmath>
#include <mutex>

namespace
{
struct Pose
{
  double x = 0.0, y = 0.0, yaw = 0.0;
};

Pose compose(const Pose& a, const Pose& b)
{
  const double c = std::cos(a.yaw), s = std::sin(a.yaw);
  return { a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, std::remainder(a.yaw + b.yaw, 2.0 * M_PI) };
}

Pose fromOdometry(const nav_msgs::Odometry& msg)
{
  return { msg.pose.pose.position.x, msg.pose.pose.position.y, tf2::getYaw(msg.pose.pose.orientation) };
}

/// Scores the run as the messages arrive (the simulator publishes odom and ground truth at the
/// same stamps).
class Scorer
{
public:
  explicit Scorer(ros::NodeHandle& nh)
    : odom_sub_(nh.subscribe("odom", 500, &Scorer::onOdom, this))
    , truth_sub_(nh.subscribe("ground_truth", 500, &Scorer::onTruth, this))
    , tf_sub_(nh.subscribe("/tf", 500, &Scorer::onTf, this))
  {}

  double kidnap_time = 1e9;  ///< [s] since the first sample; set once the kidnap is done
  int right = 0, wrong = 0, absent = 0;
  int right_after_fix = 0, wrong_after_fix = 0, samples_after_fix = 0;
  double first_fix = -1.0;   ///< [s] since the first sample
  double recovered = -1.0;   ///< [s] since the kidnap
  double now = 0.0;          ///< [s] since the first sample
  double worst_error = 0.0;  ///< [m] of a wrong sample
  std::mutex mutex;

private:
  void onOdom(const nav_msgs::Odometry& msg)
  {
    std::lock_guard<std::mutex> lock(mutex);
    odom_stamp_ = msg.header.stamp;
    odom_ = fromOdometry(msg);
  }

  void onTf(const tf2_msgs::TFMessage& msg)
  {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& t : msg.transforms)
    {
      if (t.header.frame_id == "map" && t.child_frame_id == "odom")
      {
        map_to_odom_ = { t.transform.translation.x, t.transform.translation.y, tf2::getYaw(t.transform.rotation) };
        valid_until_ = t.header.stamp;
      }
    }
  }

  void onTruth(const nav_msgs::Odometry& msg)
  {
    std::lock_guard<std::mutex> lock(mutex);
    if (start_.isZero())
    {
      start_ = msg.header.stamp;
    }
    const double t = (msg.header.stamp - start_).toSec();
    if (msg.header.stamp != odom_stamp_ || t < next_sample_)
    {
      return;
    }
    next_sample_ = t + 0.1;
    now = t;
    score(t, fromOdometry(msg));
  }

  void score(double t, const Pose& truth)
  {
    const bool present = valid_until_ >= odom_stamp_;
    const Pose pose = compose(map_to_odom_, odom_);
    const double error = std::hypot(pose.x - truth.x, pose.y - truth.y);
    const bool ok =
        present && error <= 0.1 && std::abs(std::remainder(pose.yaw - truth.yaw, 2.0 * M_PI)) <= 5.0 * M_PI / 180.0;
    (!present ? absent : ok ? right : wrong) += 1;
    if (present != was_present_)
    {
      ROS_INFO("pose %s at %.1f s", present ? "published again" : "absent", t);
      was_present_ = present;
    }
    if (ok && first_fix < 0.0)
    {
      first_fix = t;
    }
    if (first_fix >= 0.0)
    {
      ++samples_after_fix;
      right_after_fix += ok ? 1 : 0;
      wrong_after_fix += present && !ok ? 1 : 0;
    }
    if (ok && t > kidnap_time && recovered < 0.0)
    {
      recovered = t - kidnap_time;
    }
    worst_error = present && !ok ? std::max(worst_error, error) : worst_error;
    if (present && !ok)
    {
      ROS_INFO("wrong at %.1f s: %.3f m, %.1f deg off", t, error,
               std::abs(std::remainder(pose.yaw - truth.yaw, 2.0 * M_PI)) * 180.0 / M_PI);
    }
  }

private:
  ros::Subscriber odom_sub_, truth_sub_, tf_sub_;
  ros::Time start_;
  ros::Time odom_stamp_;
  ros::Time valid_until_;
  Pose odom_, map_to_odom_;
  double next_sample_ = 0.0;
  bool was_present_ = false;
};
}  // namespace

TEST(TrackingPatrol, PoseIsRightNearlyAlwaysAndNeverLongWrong)
{
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const double duration = pnh.param("duration", 120.0);
  const double kidnap_at = pnh.param("kidnap_time", 60.0);
  Scorer scorer(nh);
  ros::ServiceClient kidnap = nh.serviceClient<fdml_localization::Kidnap>("fdml_simulator/kidnap");
  ASSERT_TRUE(kidnap.waitForExistence(ros::Duration(60.0)));
  bool kidnapped = false;
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(pnh.param("wall_limit", 150.0));
  while (ros::ok() && ros::WallTime::now() < give_up)
  {
    ros::WallDuration(0.05).sleep();  // polling the scorer's counters, not synchronising
    std::lock_guard<std::mutex> lock(scorer.mutex);
    if (!kidnapped && scorer.now >= kidnap_at)
    {
      fdml_localization::Kidnap move;
      move.request.pose.x = pnh.param("kidnap_x", 4.0);
      move.request.pose.y = pnh.param("kidnap_y", 3.0);
      move.request.pose.theta = pnh.param("kidnap_theta", 0.0);
      ASSERT_TRUE(kidnap.call(move));
      ASSERT_TRUE(move.response.success) << move.response.message;
      scorer.kidnap_time = scorer.now;
      kidnapped = true;
    }
    if (scorer.now >= duration)
    {
      break;
    }
  }
  std::lock_guard<std::mutex> lock(scorer.mutex);
  const int samples = scorer.right + scorer.wrong + scorer.absent;
  ASSERT_GT(samples, 100) << "the run did not complete";
  const double right = static_cast<double>(scorer.right_after_fix) / std::max(1, scorer.samples_after_fix);
  const double wrong = static_cast<double>(scorer.wrong_after_fix) / std::max(1, scorer.samples_after_fix);
  ROS_INFO("tracking patrol: %d samples: right %.1f %%, wrong %.1f %%, absent %.1f %% (after the first fix: right "
           "%.1f %%, wrong %.1f %%); first fix at %.1f s, kidnap at %.1f s recovered after %.1f s; worst wrong %.2f m",
           samples, 100.0 * scorer.right / samples, 100.0 * scorer.wrong / samples, 100.0 * scorer.absent / samples,
           100.0 * right, 100.0 * wrong, scorer.first_fix, scorer.kidnap_time, scorer.recovered, scorer.worst_error);
  EXPECT_TRUE(kidnapped);
  EXPECT_GE(scorer.first_fix, 0.0) << "never a right pose";
  EXPECT_LE(scorer.first_fix, pnh.param("max_first_fix", 5.0));
  EXPECT_GE(right, pnh.param("min_right", 0.9));
  EXPECT_LE(wrong, pnh.param("max_wrong", 0.02));
  EXPECT_GE(scorer.recovered, 0.0) << "never right again after the kidnap";
  EXPECT_LE(scorer.recovered, pnh.param("max_recovery", 10.0));
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tracking_patrol");
  ros::AsyncSpinner spinner(2);
  spinner.start();
  const int status = RUN_ALL_TESTS();
  ros::shutdown();
  return status;
}
