// Rostest helper: collects every message of a topic and waits, with a timeout, for one that
// satisfies a predicate (callbacks are serviced by the test's AsyncSpinner).
#pragma once

#include <ros/ros.h>

#include <mutex>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace test
{
template <typename Msg>
class Collector
{
public:
  Collector(ros::NodeHandle& nh, const std::string& topic)
    : sub_(nh.subscribe<Msg>(topic, 100, [this](const typename Msg::ConstPtr& msg) {
      std::lock_guard<std::mutex> lock(mutex_);
      messages_.push_back(*msg);
    }))
  {}

  /// Waits until a received message satisfies @p pred (copied to @p found when given);
  /// false when none did within @p timeout [s] of wall time.
  template <typename Pred>
  bool waitFor(Pred pred, double timeout, Msg* found = nullptr)
  {
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
    while (ros::ok() && ros::WallTime::now() < deadline)
    {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        for (const Msg& msg : messages_)
        {
          if (pred(msg))
          {
            if (found != nullptr)
            {
              *found = msg;
            }
            return true;
          }
        }
      }
      ros::WallDuration(0.02).sleep();
    }
    return false;
  }

private:
  std::mutex mutex_;
  std::vector<Msg> messages_;
  ros::Subscriber sub_;
};

}  // namespace test
}  // namespace fdml_localization
