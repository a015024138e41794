#include "node_test_scene.h"

#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/ros/conversions.h"

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/Range.h>

namespace fdml_localization
{
namespace test
{
std::string testMapPath()
{
  return std::string(FDML_SOURCE_DIR) + "/test/data/node_test_room.poly";
}

TurningScene::TurningScene() : map(std::make_shared<const core::MapRayCaster>(core::loadPolyFile(testMapPath())))
{}

core::Pose2 TurningScene::baseInMap(int j) const
{
  return core::Pose2(start.x, start.y, core::wrapAngle(start.theta + j * core::kTwoPi / k));
}

core::Pose2 TurningScene::baseInOdom(int j) const
{
  return core::compose(core::inverse(map_to_odom), baseInMap(j));
}

bool TurningScene::occluded(int j) const
{
  const int phase = ((j % k) + k) % k;
  return phase == 3 || phase == 7;
}

double TurningScene::range(int j) const
{
  const double h = map->range(core::compose(baseInMap(j), mount), max_range);
  return occluded(j) ? 0.5 * h : h;
}

std::vector<fdml_localization::Reading> TurningScene::readings(int first, int count) const
{
  std::vector<fdml_localization::Reading> out;
  for (int j = first; j < first + count; ++j)
  {
    core::Reading reading;
    reading.offset = core::compose(core::between(baseInMap(first), baseInMap(j)), mount);
    reading.range = range(j);
    reading.max_range = max_range;
    out.push_back(toReadingMsg(reading));
  }
  return out;
}

ScenePublisher::ScenePublisher(ros::NodeHandle& nh, const TurningScene& scene)
  : scene_(scene)
  , range_pub_(nh.advertise<sensor_msgs::Range>("range", 100))
  , scan_pub_(nh.advertise<sensor_msgs::LaserScan>("scan", 10))
{
  geometry_msgs::TransformStamped mount;
  mount.header.stamp = ros::Time::now();
  mount.header.frame_id = "base_link";
  mount.child_frame_id = "range_sensor";
  mount.transform = toTransformMsg(scene_.mount);
  geometry_msgs::TransformStamped laser = mount;
  laser.child_frame_id = "laser";
  laser.transform = toTransformMsg(scene_.laser_mount);
  static_broadcaster_.sendTransform(std::vector<geometry_msgs::TransformStamped>{ mount, laser });
}

bool ScenePublisher::waitForSubscribers(std::uint32_t nodes, double timeout)
{
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  const auto ready = [this, nodes]() {
    return range_pub_.getNumSubscribers() >= nodes && scan_pub_.getNumSubscribers() >= nodes;
  };
  while (!ready() && ros::WallTime::now() < deadline && ros::ok())
  {
    ros::WallDuration(0.01).sleep();
  }
  return ready();
}

ros::Time ScenePublisher::nextStamp()
{
  ros::Time stamp = ros::Time::now();
  if (stamp <= last_stamp_)
  {
    stamp = last_stamp_ + ros::Duration(0, 1000);
  }
  last_stamp_ = stamp;
  return stamp;
}

void ScenePublisher::publishOdom(int j, const ros::Time& stamp)
{
  geometry_msgs::TransformStamped odom;
  odom.header.stamp = stamp;
  odom.header.frame_id = "odom";
  odom.child_frame_id = "base_link";
  odom.transform = toTransformMsg(scene_.baseInOdom(j));
  broadcaster_.sendTransform(odom);
  index_of_stamp_[stamp] = j;
}

ros::Time ScenePublisher::publishReading(int j)
{
  const ros::Time stamp = nextStamp();
  publishOdom(j, stamp);
  publishRange(scene_.range(j), "range_sensor", stamp);
  return stamp;
}

ros::Time ScenePublisher::publishScan(int j)
{
  const ros::Time stamp = nextStamp();
  publishOdom(j, stamp);
  sensor_msgs::LaserScan scan;
  scan.header.stamp = stamp;
  scan.header.frame_id = "laser";
  scan.angle_min = static_cast<float>(-core::kPi);
  scan.angle_increment = static_cast<float>(core::kTwoPi / 360.0);
  scan.angle_max = static_cast<float>(-core::kPi + 359.0 * core::kTwoPi / 360.0);
  scan.range_min = 0.02f;
  scan.range_max = static_cast<float>(scene_.max_range);
  const core::Pose2 laser = core::compose(scene_.baseInMap(j), scene_.laser_mount);
  for (int i = 0; i < 360; ++i)
  {
    const double angle = scan.angle_min + i * static_cast<double>(scan.angle_increment);
    const double range = scene_.map->range(core::compose(laser, core::Pose2(0.0, 0.0, angle)), scene_.max_range);
    scan.ranges.push_back(static_cast<float>(range));
  }
  scan_pub_.publish(scan);
  return stamp;
}

void ScenePublisher::publishRange(double range, const std::string& frame, const ros::Time& stamp)
{
  sensor_msgs::Range msg;
  msg.header.stamp = stamp;
  msg.header.frame_id = frame;
  msg.radiation_type = sensor_msgs::Range::INFRARED;
  msg.field_of_view = 0.0f;  // the scene computes its ranges as rays
  msg.min_range = 0.02f;
  msg.max_range = static_cast<float>(scene_.max_range);
  msg.range = static_cast<float>(range);
  range_pub_.publish(msg);
}

int ScenePublisher::indexOf(const ros::Time& stamp) const
{
  const auto it = index_of_stamp_.find(stamp);
  return it == index_of_stamp_.end() ? -1 : it->second;
}

}  // namespace test
}  // namespace fdml_localization
