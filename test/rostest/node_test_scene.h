/**
 * @file node_test_scene.h
 * @brief Ground truth for the localizer node rostests: a robot turning in place in the test
 *        room, a range sensor on it, and an unknown obstacle cutting two of every ten readings
 *        short. Expected ranges come from the core MapRayCaster, independently of the node.
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"

#include <fdml_localization/Reading.h>
#include <ros/ros.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace test
{
/// The test room (test/data/node_test_room.poly) as a file path.
std::string testMapPath();

struct TurningScene
{
  TurningScene();

  std::shared_ptr<const core::MapRayCaster> map;
  core::Pose2 start{ 2.8, 1.2, 0.3 };           ///< base in the map at reading 0
  core::Pose2 map_to_odom{ 0.7, -0.4, 0.9 };    ///< the true map -> odom transform
  core::Pose2 mount{ 0.12, 0.03, 0.0 };         ///< base_link -> range_sensor
  core::Pose2 laser_mount{ 0.05, -0.02, 0.0 };  ///< base_link -> laser
  int k = 10;                                   ///< readings per turn (2 pi / k apart)
  double max_range = 8.0;                       ///< [m]

  /// Base pose in the map at reading j: turning in place by 2 pi / k per reading.
  core::Pose2 baseInMap(int j) const;
  core::Pose2 baseInOdom(int j) const;
  /// True when reading j hits the unknown obstacle (j mod k is 3 or 7).
  bool occluded(int j) const;
  /// The measured range of reading j: the map's range, halved when occluded [m].
  double range(int j) const;
  /// Readings first..first+count-1 as the localizer consumes them (g_i relative to reading first).
  std::vector<fdml_localization::Reading> readings(int first, int count) const;
};

/// Publishes the scene on tf and on the range topic, one reading at a time.
class ScenePublisher
{
public:
  ScenePublisher(ros::NodeHandle& nh, const TurningScene& scene);

  /// Waits until @p nodes subscribers are connected to both the range and the scan topic
  /// (messages published earlier would be lost for the late ones); false on timeout.
  bool waitForSubscribers(std::uint32_t nodes, double timeout);
  /// Publishes odom -> base_link and the Range of reading j, stamped now; returns the stamp.
  ros::Time publishReading(int j);
  /// Publishes odom -> base_link and a 360-beam LaserScan (no obstacle) at reading j's pose.
  ros::Time publishScan(int j);
  /// Publishes a raw Range (for malformed input).
  void publishRange(double range, const std::string& frame, const ros::Time& stamp);
  /// The reading index published with @p stamp, -1 when unknown.
  int indexOf(const ros::Time& stamp) const;

private:
  const TurningScene& scene_;
  ros::Time nextStamp();
  void publishOdom(int j, const ros::Time& stamp);

  ros::Publisher range_pub_;
  ros::Publisher scan_pub_;
  tf2_ros::TransformBroadcaster broadcaster_;
  tf2_ros::StaticTransformBroadcaster static_broadcaster_;
  std::map<ros::Time, int> index_of_stamp_;
  ros::Time last_stamp_;
};

}  // namespace test
}  // namespace fdml_localization
