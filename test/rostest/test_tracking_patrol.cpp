// A whole simulated patrol scored against the ground truth (issue 17): every 0.1 s of simulated
// time the published map -> odom (while it is current: stamped at or after that time, as the
// localizer future-dates it) composed with the odometry is right (10 cm, 5 deg), wrong, or
// absent. The robot is kidnapped at ~kidnap_time (none when negative). Asserts the fractions, the
// time to the first fix (within [~min_first_fix, ~max_first_fix]), that no wrong pose came before
// it, and the time to recover from the kidnap (limits are the test node's private parameters).
#include "tracking_scorer.h"

#include <fdml_localization/Kidnap.h>
#include <fdml_localization/Status.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2/utils.h>
#include <tf2_msgs/TFMessage.h>

#include <gtest/gtest.h>

#include <cmath>
#include <mutex>

using fdml_test::Scorer;

TEST(TrackingPatrol, PoseIsRightNearlyAlwaysAndNeverLongWrong)
{
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  const double duration = pnh.param("duration", 120.0);
  const double kidnap_at = pnh.param("kidnap_time", 60.0);
  const bool kidnapping = kidnap_at >= 0.0;
  Scorer scorer(nh);
  ros::ServiceClient kidnap = nh.serviceClient<fdml_localization::Kidnap>("fdml_simulator/kidnap");
  ASSERT_TRUE(kidnap.waitForExistence(ros::Duration(60.0)));
  bool kidnapped = false;
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(pnh.param("wall_limit", 150.0));
  while (ros::ok() && ros::WallTime::now() < give_up)
  {
    ros::WallDuration(0.05).sleep();  // polling the scorer's counters, not synchronising
    std::lock_guard<std::mutex> lock(scorer.mutex);
    if (kidnapping && !kidnapped && scorer.now >= kidnap_at)
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
  EXPECT_GE(scorer.first_fix, 0.0) << "never a right pose";
  EXPECT_LE(scorer.first_fix, pnh.param("max_first_fix", 5.0));
  // Where the readings cannot tell places apart (twin rooms) not even the right pose may come early.
  EXPECT_GE(scorer.first_fix, pnh.param("min_first_fix", 0.0)) << "a pose before the place could be told apart";
  EXPECT_EQ(scorer.wrong - scorer.wrong_after_fix, 0) << "a wrong pose before the first fix";
  EXPECT_GE(right, pnh.param("min_right", 0.9));
  EXPECT_LE(wrong, pnh.param("max_wrong", 0.02));
  if (kidnapping)
  {
    EXPECT_TRUE(kidnapped);
    EXPECT_GE(scorer.recovered, 0.0) << "never right again after the kidnap";
    EXPECT_LE(scorer.recovered, pnh.param("max_recovery", 10.0));
  }
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
