// Scores a localizer's published pose against the simulator's ground truth (tracking rostests):
// every 0.1 s of simulated time the newest map -> odom on /tf (while it is current: stamped at or
// after that time, as the localizer future-dates it) composed with the odometry is right (10 cm,
// 5 deg), wrong, or absent.
#pragma once

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2/utils.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <mutex>
#include <utility>

namespace fdml_test
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
    latest_truth = fromOdometry(msg);
    history_.emplace_back(msg.header.stamp, latest_truth);
    while (history_.size() > 5000)
    {
      history_.pop_front();
    }
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

public:
  Pose latest_truth;

  /// The true pose nearest @p stamp (call with the lock held); false when none is near.
  bool truthAt(const ros::Time& stamp, Pose* pose) const
  {
    for (auto it = history_.rbegin(); it != history_.rend(); ++it)
    {
      if (std::abs((it->first - stamp).toSec()) <= 0.02)
      {
        *pose = it->second;
        return true;
      }
    }
    return false;
  }

  /// Restarts the counts after the first fix (call with the lock held).
  void restartCounts()
  {
    right_after_fix = wrong_after_fix = samples_after_fix = 0;
  }

private:
  std::deque<std::pair<ros::Time, Pose>> history_;
  ros::Subscriber odom_sub_, truth_sub_, tf_sub_;
  ros::Time start_;
  ros::Time odom_stamp_;
  ros::Time valid_until_;
  Pose odom_, map_to_odom_;
  double next_sample_ = 0.0;
  bool was_present_ = false;
};
}  // namespace fdml_test
