// rostest of fdml_simulator: every published reading is checked against an independent ray
// cast (core MapRayCaster plus the obstacles as published on obstacle_markers) at the sensor
// pose built from the ground_truth topic and the static tf of the sensor mounting.
#include "simulator_fixture.h"

#include "fdml_localization/Kidnap.h"
#include "fdml_localization/core/geometry/cone_cast.h"

#include <std_srvs/Empty.h>

namespace
{
class Noiseless : public SimulatorTest
{};

class Obstacles : public SimulatorTest
{};

void expectRangeEq(double actual, double expected, double tolerance, const std::string& what)
{
  if (std::isinf(expected))
  {
    EXPECT_TRUE(std::isinf(actual) && actual > 0) << what << ": " << actual << " vs +inf";
  }
  else
  {
    EXPECT_NEAR(actual, expected, tolerance) << what;
  }
}
}  // namespace

TEST_F(Noiseless, EveryRangeEqualsAnIndependentRayCast)
{
  ASSERT_TRUE(waitFor([this]() { return ranges_.size() >= 300; })) << ranges_.size() << " ranges";
  std::map<std::string, int> per_frame;
  int checked = 0;
  int misses = 0;
  const std::vector<sensor_msgs::Range> ranges = ranges_;  // mount() spins: iterate over a copy
  for (const auto& r : ranges)
  {
    auto gt = gt_.find(r.header.stamp);
    if (gt == gt_.end())
    {
      continue;  // its ground truth has not arrived yet
    }
    const core::Pose2 sensor = core::compose(gt->second, mount(r.header.frame_id));
    // A sensor with a field of view reads the nearest point within its cone (brute force).
    const double expected =
        core::coneRangeBruteForce(caster_->grid().segments(), sensor, 0.5 * r.field_of_view, r.max_range);
    expectRangeEq(r.range, expected, 1e-4, r.header.frame_id);
    per_frame[r.header.frame_id]++;
    misses += std::isinf(expected) ? 1 : 0;
    ++checked;
  }
  EXPECT_GE(checked, 250);
  EXPECT_EQ(per_frame.size(), 3u);
  EXPECT_GT(misses, 0) << "the 1.5 m sensor should sometimes see nothing";
  // Every reading has its ground-truth label (no dropout here, no obstacles).
  const std::size_t published = ranges_.size();
  ASSERT_TRUE(waitFor([&]() { return truths_.size() >= published; }));
  for (const auto& t : truths_)
  {
    EXPECT_FALSE(t.dropped);
    EXPECT_NE(t.hit, fl::ReadingTruth::HIT_OBSTACLE);
    EXPECT_EQ(t.hit == fl::ReadingTruth::HIT_NONE, std::isinf(t.true_range));
  }
}

TEST_F(Noiseless, ScanBeamsEqualIndependentRayCasts)
{
  ASSERT_TRUE(waitFor([this]() { return scans_.size() >= 20; }));
  const core::Pose2 mounting = mount("base_scan");
  const std::vector<sensor_msgs::LaserScan> scans = scans_;
  int checked = 0;
  for (const auto& scan : scans)
  {
    auto gt = gt_.find(scan.header.stamp);
    if (gt == gt_.end())
    {
      continue;
    }
    ASSERT_EQ(scan.ranges.size(), 12u);
    const core::Pose2 base = core::compose(gt->second, mounting);
    for (std::size_t b = 0; b < scan.ranges.size(); ++b)
    {
      const double angle = scan.angle_min + static_cast<double>(b) * scan.angle_increment;
      const core::Pose2 beam = core::compose(base, core::Pose2(0.0, 0.0, angle));
      expectRangeEq(scan.ranges[b], caster_->range(beam, scan.range_max), 1e-3, "beam " + std::to_string(b));
    }
    ++checked;
  }
  EXPECT_GE(checked, 15);
}

TEST_F(Noiseless, OccupancyGridMarksTheRobotCellFree)
{
  ASSERT_TRUE(waitFor([this]() { return !grids_.empty() && !gt_.empty(); }));
  const nav_msgs::OccupancyGrid& grid = grids_.front();
  EXPECT_EQ(grid.header.frame_id, "map");
  EXPECT_NEAR(grid.info.resolution, 0.1, 1e-6);
  auto cell = [&grid](double x, double y) {
    const auto col = static_cast<std::size_t>((x - grid.info.origin.position.x) / grid.info.resolution);
    const auto row = static_cast<std::size_t>((y - grid.info.origin.position.y) / grid.info.resolution);
    return grid.data.at(row * grid.info.width + col);
  };
  const core::Pose2 robot = gt_.rbegin()->second;
  EXPECT_EQ(cell(robot.x, robot.y), 0);
  EXPECT_EQ(cell(3.75, 1.75), 100);  // the pillar
  EXPECT_EQ(cell(1.0, 3.5), -1);     // outside the L
}

TEST_F(Noiseless, OdometryAgreesWithGroundTruth)
{
  ASSERT_TRUE(waitFor([this]() { return odom_.size() >= 300 && gt_.size() >= 300; }));
  bool have_first = false;
  core::Pose2 map_to_odom;
  core::Pose2 first_gt;
  double travelled = 0.0;
  int pairs = 0;
  for (const auto& o : odom_)
  {
    auto gt = gt_.find(o.first);
    if (gt == gt_.end())
    {
      continue;
    }
    const core::Pose2 t = core::compose(gt->second, core::inverse(o.second));
    if (!have_first)
    {
      have_first = true;
      map_to_odom = t;
      first_gt = gt->second;
    }
    EXPECT_NEAR(t.x, map_to_odom.x, 1e-6);
    EXPECT_NEAR(t.y, map_to_odom.y, 1e-6);
    EXPECT_NEAR(core::angleDiff(t.theta, map_to_odom.theta), 0.0, 1e-6);
    travelled = std::max(travelled, (gt->second.position() - first_gt.position()).norm());
    ++pairs;
  }
  EXPECT_GE(pairs, 250);
  EXPECT_GT(travelled, 0.5) << "the robot should have moved";
  // tf odom -> base_link carries the same pose as the odom topic.
  const ros::Time stamp = odom_.rbegin()->first;
  std::string error;
  ASSERT_TRUE(waitFor([&]() { return tf_buffer_->canTransform("odom", "base_link", stamp, &error); })) << error;
  const core::Pose2 tf = fl::fromTransformMsg(tf_buffer_->lookupTransform("odom", "base_link", stamp).transform);
  EXPECT_NEAR(tf.x, odom_.rbegin()->second.x, 1e-9);
  EXPECT_NEAR(tf.y, odom_.rbegin()->second.y, 1e-9);
  EXPECT_NEAR(core::angleDiff(tf.theta, odom_.rbegin()->second.theta), 0.0, 1e-9);
}

TEST_F(Noiseless, KidnapMovesGroundTruthButNotOdometry)
{
  ros::ServiceClient client = nh_.serviceClient<fl::Kidnap>("/fdml_simulator/kidnap");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(kWaitSeconds)));
  ASSERT_TRUE(waitFor([this]() { return gt_.size() >= 10; }));

  const core::Pose2 target(5.5, 0.5, 1.0);
  ASSERT_GT((gt_.rbegin()->second.position() - target.position()).norm(), 1.0);
  fl::Kidnap kidnap;
  kidnap.request.random = false;
  kidnap.request.pose = fl::toPose2D(target);
  ASSERT_TRUE(client.call(kidnap));
  ASSERT_TRUE(kidnap.response.success) << kidnap.response.message;
  EXPECT_NEAR(kidnap.response.pose.x, target.x, 1e-9);

  // The first ground truth at the target, and the one just before it.
  auto at_target = [this, &target]() {
    for (std::size_t i = 1; i < gt_order_.size(); ++i)
    {
      if ((gt_[gt_order_[i]].position() - target.position()).norm() < 0.05)
      {
        return static_cast<int>(i);
      }
    }
    return -1;
  };
  ASSERT_TRUE(waitFor([&]() { return at_target() > 0; }));
  const ros::Time after = gt_order_[static_cast<std::size_t>(at_target())];
  const ros::Time before = gt_order_[static_cast<std::size_t>(at_target()) - 1];
  EXPECT_GT((gt_[after].position() - gt_[before].position()).norm(), 1.0);
  ASSERT_TRUE(waitFor([&]() { return odom_.count(after) > 0 && odom_.count(before) > 0; }));
  const core::Pose2 odom_step = core::between(odom_[before], odom_[after]);
  EXPECT_LT(std::hypot(odom_step.x, odom_step.y), 0.05) << "odometry saw the kidnapping";
  EXPECT_LT(std::abs(odom_step.theta), 0.1);
}

TEST_F(Noiseless, KidnapRefusesAPoseInAnObstacleAndRandomKidnapsLandInFreeSpace)
{
  ros::ServiceClient client = nh_.serviceClient<fl::Kidnap>("/fdml_simulator/kidnap");
  ASSERT_TRUE(client.waitForExistence(ros::Duration(kWaitSeconds)));
  // A pose inside the pillar is refused with a reason.
  fl::Kidnap bad;
  bad.request.pose = fl::toPose2D(core::Pose2(3.75, 1.75, 0.0));
  ASSERT_TRUE(client.call(bad));
  EXPECT_FALSE(bad.response.success);
  EXPECT_FALSE(bad.response.message.empty());

  // A random kidnap lands in free space.
  fl::Kidnap random;
  random.request.random = true;
  ASSERT_TRUE(client.call(random));
  EXPECT_TRUE(random.response.success) << random.response.message;
  EXPECT_TRUE(caster_->isFree(core::Vec2(random.response.pose.x, random.response.pose.y)));
}

TEST_F(Noiseless, ResetRestoresTheStartAndZeroesOdometry)
{
  ASSERT_TRUE(waitFor([this]() { return gt_.size() >= 2; }));
  // ~reset brings the robot back to its start (the first waypoint) and odometry to zero.
  ros::ServiceClient reset = nh_.serviceClient<std_srvs::Empty>("/fdml_simulator/reset");
  std_srvs::Empty empty;
  ASSERT_TRUE(reset.call(empty));
  const core::Pose2 start(1.0, 1.0, 0.0);
  const std::size_t seen = gt_order_.size();
  auto back_at_start = [&]() {
    for (std::size_t i = seen; i < gt_order_.size(); ++i)
    {
      if ((gt_[gt_order_[i]].position() - start.position()).norm() < 0.05 && odom_.count(gt_order_[i]) > 0)
      {
        return true;
      }
    }
    return false;
  };
  ASSERT_TRUE(waitFor(back_at_start));
  for (std::size_t i = seen; i < gt_order_.size(); ++i)
  {
    if ((gt_[gt_order_[i]].position() - start.position()).norm() < 0.05 && odom_.count(gt_order_[i]) > 0)
    {
      EXPECT_LT(odom_[gt_order_[i]].position().norm(), 0.05);
      break;
    }
  }
}

/// What a ray sees among the static map and the obstacles as published.
struct IndependentCast
{
  double range = core::kInf;
  int kind = fl::ReadingTruth::HIT_NONE;
  int id = -1;
};

/// Independent cast of the cone of half-angle @p half_angle: the static map's range @p map_range,
/// then every obstacle as published.
IndependentCast castWithObstacles(const core::Pose2& sensor, double half_angle, double max_range, double map_range,
                                  const std::vector<visualization_msgs::Marker>& obstacles)
{
  const core::Sector sector = core::Sector::around(sensor, half_angle);
  IndependentCast cast;
  cast.range = map_range;
  cast.kind = std::isinf(map_range) ? fl::ReadingTruth::HIT_NONE : fl::ReadingTruth::HIT_MAP;
  for (const auto& o : obstacles)
  {
    double d = core::kInf;
    if (o.type == visualization_msgs::Marker::CYLINDER)
    {
      d = core::sectorCircleDistance(sector, core::Vec2(o.pose.position.x, o.pose.position.y), 0.5 * o.scale.x);
    }
    for (std::size_t k = 0; o.type != visualization_msgs::Marker::CYLINDER && k + 1 < o.points.size(); ++k)
    {
      const core::Segment edge{ core::Vec2(o.points[k].x, o.points[k].y),
                                core::Vec2(o.points[k + 1].x, o.points[k + 1].y) };
      d = std::min(d, core::sectorSegmentDistance(sector, edge));
    }
    if (d <= max_range && d < cast.range)
    {
      cast = { d, fl::ReadingTruth::HIT_OBSTACLE, o.id };
    }
  }
  return cast;
}

TEST_F(Obstacles, HitLabelsMatchIndependentCasts)
{
  ASSERT_TRUE(waitFor([this]() { return truths_.size() >= 600; })) << truths_.size() << " readings";
  std::map<std::string, double> max_range;
  std::map<std::string, double> half_angle;
  ASSERT_TRUE(waitFor([&]() { return !ranges_.empty(); }));
  for (const auto& r : ranges_)
  {
    max_range[r.header.frame_id] = r.max_range;
    half_angle[r.header.frame_id] = 0.5 * r.field_of_view;
  }
  std::map<int, int> kinds;
  int checked = 0;
  const std::vector<fl::ReadingTruth> truths = truths_;  // mount() spins: iterate over a copy
  for (const auto& t : truths)
  {
    auto gt = gt_.find(t.header.stamp);
    auto obstacles = obstacles_.find(t.header.stamp);
    if (gt == gt_.end() || obstacles == obstacles_.end() || max_range.count(t.header.frame_id) == 0)
    {
      continue;
    }
    const double m = max_range[t.header.frame_id];
    const core::Pose2 sensor = core::compose(gt->second, mount(t.header.frame_id));
    EXPECT_NEAR(t.sensor_pose.x, sensor.x, 1e-9);
    EXPECT_NEAR(t.sensor_pose.y, sensor.y, 1e-9);
    const double a = half_angle[t.header.frame_id];
    const double map_range = core::coneRangeBruteForce(caster_->grid().segments(), sensor, a, m);
    const IndependentCast cast = castWithObstacles(sensor, a, m, map_range, obstacles->second);
    const double best = cast.range;
    EXPECT_EQ(t.hit, cast.kind) << "reading at " << t.header.stamp << " from " << t.header.frame_id;
    EXPECT_EQ(t.obstacle_id, cast.id);
    expectRangeEq(t.true_range, best, 1e-9, "true_range");
    expectRangeEq(t.map_range, map_range, 1e-9, "map_range");
    expectRangeEq(t.range, best, 1e-9, "range (noise 0)");
    EXPECT_EQ(t.hit == fl::ReadingTruth::HIT_OBSTACLE, t.true_range < t.map_range);
    kinds[t.hit]++;
    ++checked;
  }
  EXPECT_GE(checked, 500);
  EXPECT_GE(kinds[fl::ReadingTruth::HIT_OBSTACLE], 20) << "obstacles should be hit";
  EXPECT_GE(kinds[fl::ReadingTruth::HIT_MAP], 20) << "walls should be hit";
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_simulator");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
