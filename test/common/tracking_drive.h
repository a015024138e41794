// A ROS-free drive for tracker tests and benchmarks: steps a Simulation and forms the batches
// the node forms (the last k readings, g_i relative to the odometry base pose at the first one,
// a new batch every `stride` readings), each with the true pose of the base at its first reading.
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/tracking/hypothesis_tracker.h"
#include "fdml_localization/simulation/simulation.h"

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <deque>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace fdml_test
{
namespace core = fdml_localization::core;

/// One batch as the node forms it.
struct DriveBatch
{
  std::vector<core::Reading> readings;
  core::Pose2 reference;    ///< odometry pose of the base at the first reading
  core::Pose2 truth;        ///< true pose of the base at the first reading (map)
  double start_time = 0.0;  ///< simulated time of the oldest reading [s]
  double time = 0.0;        ///< simulated time of the newest reading [s]
  int obstacle_hits = 0;    ///< readings that hit an unknown obstacle
};

/// See the file comment.
class Drive
{
public:
  /// @p per_reading: a batch may form after any reading, as the node forms them (readings of one
  /// step one by one); otherwise only after a whole simulation step.
  Drive(std::unique_ptr<core::Simulation> sim, int k, int stride, bool per_reading = false)
    : sim_(std::move(sim)), k_(k), stride_(stride), per_reading_(per_reading)
  {}

  /// Steps until the next batch is due; false after @p max_time simulated seconds.
  bool next(DriveBatch* batch, double max_time)
  {
    while (!pending_.empty() || sim_->time() < max_time)
    {
      if (pending_.empty())
      {
        core::StepOutput out;
        sim_->step(&out);
        for (const core::SimReading& r : out.readings)
        {
          pending_.push_back(Pending{ r, sim_->odomPose(), sim_->truePose() });
        }
      }
      while (!pending_.empty())
      {
        take(pending_.front());
        pending_.pop_front();
        if (per_reading_ && due())
        {
          fill(batch);
          return true;
        }
      }
      if (!per_reading_ && due())
      {
        fill(batch);
        return true;
      }
    }
    return false;
  }

  core::Simulation& sim()
  {
    return *sim_;
  }

private:
  struct Entry
  {
    core::Pose2 odom_base, truth_base, sensor_in_odom;
    double range = 0.0, max_range = 0.0, half_angle = 0.0, time = 0.0;
    bool obstacle = false;
  };

  struct Pending
  {
    core::SimReading reading;
    core::Pose2 odom_base, truth_base;
  };

  /// Adds @p p to the window (the newest k readings) unless it was lost.
  void take(const Pending& p)
  {
    const core::SimReading& r = p.reading;
    const auto& sensor = sim_->config().sensors[r.sensor];
    if (r.dropped || std::isnan(r.range) || r.range == -core::kInf)
    {
      return;
    }
    Entry e;
    e.odom_base = p.odom_base;
    e.truth_base = p.truth_base;
    e.sensor_in_odom = core::compose(e.odom_base, sensor.mount);
    e.range = r.range;
    e.max_range = sensor.max_range;
    e.half_angle = 0.5 * sensor.fov;  // the simulator reads a cone when fov > 0
    e.obstacle = r.kind == core::SceneHit::Kind::Obstacle;
    e.time = r.time;
    window_.push_back(e);
    ++since_batch_;
    while (static_cast<int>(window_.size()) > k_)
    {
      window_.pop_front();
    }
  }

  /// True (and counting restarts) when the window is full and stride readings came since the last batch.
  bool due()
  {
    if (static_cast<int>(window_.size()) < k_ || since_batch_ < stride_)
    {
      return false;
    }
    since_batch_ = 0;
    return true;
  }

  void fill(DriveBatch* batch) const
  {
    batch->readings.clear();
    batch->obstacle_hits = 0;
    batch->reference = window_.front().odom_base;
    batch->truth = window_.front().truth_base;
    batch->start_time = window_.front().time;
    batch->time = window_.back().time;
    for (const Entry& e : window_)
    {
      core::Reading reading;
      reading.offset = core::between(batch->reference, e.sensor_in_odom);
      reading.range = e.range;
      reading.max_range = e.max_range;
      reading.half_angle = e.half_angle;
      batch->readings.push_back(reading);
      batch->obstacle_hits += e.obstacle ? 1 : 0;
    }
  }

  std::unique_ptr<core::Simulation> sim_;
  int k_;
  int stride_;
  bool per_reading_;
  int since_batch_ = 0;
  std::deque<Entry> window_;
  std::deque<Pending> pending_;
};

/// The simulation of @p config on @p map; throws std::invalid_argument naming the config's
/// first error.
inline std::unique_ptr<core::Simulation> simulate(const core::ScenarioConfig& config,
                                                  std::shared_ptr<const core::MapRayCaster> map)
{
  std::vector<std::string> errors;
  auto sim = core::Simulation::create(config, std::move(map), &errors);
  if (!sim || !errors.empty())
  {
    throw std::invalid_argument("scenario: " + (errors.empty() ? std::string("not created") : errors.front()));
  }
  return sim;
}

/// Right as the rostests score it: within 10 cm and 5 deg of @p truth.
inline bool right(const core::Pose2& pose, const core::Pose2& truth)
{
  return (pose.position() - truth.position()).norm() <= 0.1 &&
         std::abs(core::angleDiff(pose.theta, truth.theta)) <= 5.0 * M_PI / 180.0;
}

/**
 * @brief Scores what @p tracker publishes after its update on @p batch: counts a clearly
 *        supported hypothesis in @p published and, when it is not right(), in @p wrong.
 * @return empty, or what a wrong published pose was (for a failure message)
 */
inline std::string scorePublished(const core::HypothesisTracker& tracker, const DriveBatch& batch, int* published,
                                  int* wrong)
{
  const core::Hypothesis* best = tracker.clearlySupported();
  if (!best)
  {
    return std::string();
  }
  ++*published;
  const core::Pose2 pose = core::compose(best->map_to_odom, batch.reference);
  if (right(pose, batch.truth))
  {
    return std::string();
  }
  ++*wrong;
  char text[200];
  std::snprintf(text, sizeof(text), "published (%.3f, %.3f, %.3f) at %.2f s, the truth (%.3f, %.3f, %.3f)", pose.x,
                pose.y, pose.theta, batch.time, batch.truth.x, batch.truth.y, batch.truth.theta);
  return text;
}

/// The tracker's options for the drives' odometry: a random walk of 3 % per square-root metre and
/// radian, no heading noise from translation. Drive forms one batch per simulation step when the
/// four sensors fire together (every 4 readings, 4 cm at 0.4 m/s), where alpha3 0.15 gives twice
/// that variance per metre; the node tracks every batch of ~batch_stride 2 (2 cm), and its
/// rostests set 0.21 for the same variance per metre.
inline core::TrackerOptions driveTrackerOptions()
{
  core::TrackerOptions o;
  o.odom_alpha2 = 0.05;
  o.odom_alpha3 = 0.15;
  o.odom_alpha4 = 0.1;
  // The drives seed the truth (or one global search's candidates) by hand: no later search
  // confirms them (HypothesisTracker.TwinRoomsFromGlobalSearches runs the node's searches).
  o.confirm_searches = 0;
  return o;
}

/// The node's tracking global search (SolverWorker::globalLocalizerFor): the adaptive engine at
/// @p resolution cells and range tolerance @p tau [m], one thread as in the tracking launches.
inline core::LocalizerOptions globalSearchOptions(int resolution, double tau)
{
  core::LocalizerOptions g;
  g.engine = core::Engine::Adaptive;
  g.resolution = resolution;
  g.range_tolerance = tau;
  g.threads = 1;
  return g;
}

/// The node's tracker as the launches run it: @p o (config/localizer.yaml's settings) with
/// @p search's tolerances, fix_covariance_scale k / ~batch_stride as the node sets it (k = 10),
/// and @p driving (stride 2: tracking_patrol.test, tracking_office.test) the rostests' odometry
/// noise; otherwise stride 1 (the demo, turning in place).
inline core::TrackerOptions launchTrackerOptions(core::TrackerOptions o, const core::LocalizerOptions& search,
                                                 bool driving)
{
  o.range_tolerance = search.range_tolerance;
  o.agreement_tolerance = search.agreement_tolerance;
  o.fix_covariance_scale = driving ? 5.0 : 10.0;
  if (driving)
  {
    o.odom_alpha2 = 0.05;
    o.odom_alpha3 = 0.21;
    o.odom_alpha4 = 0.1;
  }
  return o;
}

/// @p count people walking at random at @p speed [m/s], discs of @p radius [m].
inline core::ObstacleGroupConfig walkers(int count, double radius, double speed)
{
  core::ObstacleGroupConfig g;
  g.count = count;
  g.radius = radius;
  g.motion = core::ObstacleMotion::RandomWalk;
  g.speed = speed;
  return g;
}

/// @p count people pacing the polyline @p waypoints [m] at @p speed [m/s], discs of @p radius [m].
inline core::ObstacleGroupConfig pacers(int count, double radius, double speed, std::vector<core::Vec2> waypoints)
{
  core::ObstacleGroupConfig g;
  g.count = count;
  g.radius = radius;
  g.motion = core::ObstacleMotion::Waypoints;
  g.speed = speed;
  g.waypoints = std::move(waypoints);
  return g;
}

/// Four range sensors (front, left, back, right), rays, at @p rate [Hz].
inline std::vector<core::SensorConfig> fourSensors(double rate, double max_range, double noise)
{
  std::vector<core::SensorConfig> sensors;
  const char* frames[] = { "front", "left", "back", "right" };
  for (int i = 0; i < 4; ++i)
  {
    core::SensorConfig s;
    s.frame = frames[i];
    const double a = i * 0.5 * M_PI;
    s.mount = core::Pose2(0.15 * std::cos(a), 0.15 * std::sin(a), a);
    s.rate = rate;
    s.max_range = max_range;
    s.noise_sigma = noise;
    s.fov = 0.0;  // rays (the tracker's drives before cones were modelled)
    sensors.push_back(s);
  }
  return sensors;
}

/// A robot driving a loop of @p waypoints (starting at the first) at 0.4 m/s with fourSensors(10 Hz,
/// @p max_range, 1 cm noise) and odometry drifting by @p drift per metre and per radian.
inline core::ScenarioConfig waypointScenario(std::vector<core::Vec2> waypoints, double max_range, double drift,
                                             std::uint64_t seed)
{
  core::ScenarioConfig c;
  c.seed = seed;
  c.step_rate = 50;
  c.robot.radius = 0.18;
  c.robot.random_start = false;
  c.robot.start = core::Pose2(waypoints.front().x(), waypoints.front().y(), 0.0);
  c.robot.motion = core::RobotMotion::Waypoints;
  c.robot.linear_speed = 0.4;
  c.robot.angular_speed = 0.8;
  c.robot.waypoints = std::move(waypoints);
  c.sensors = fourSensors(10.0, max_range, 0.01);
  c.odometry.rate = 50;
  c.odometry.translation_noise = drift;
  c.odometry.rotation_noise = drift;
  return c;
}

/// The apartment patrol (config/scenarios/apartment_patrol.yaml): four rooms through their doors,
/// 3 % odometry drift, @p people walking at random.
inline core::ScenarioConfig apartmentPatrol(int people)
{
  core::ScenarioConfig c = waypointScenario({ { 1.5, 1.0 },
                                              { 5.5, 1.0 },
                                              { 5.5, 2.0 },
                                              { 8.3, 2.0 },
                                              { 8.3, 3.3 },
                                              { 11.3, 3.3 },
                                              { 11.3, 0.8 },
                                              { 8.3, 0.8 },
                                              { 8.3, 2.0 },
                                              { 2.8, 2.0 },
                                              { 2.8, 5.7 },
                                              { 8.0, 5.7 },
                                              { 8.0, 7.5 },
                                              { 10.5, 7.5 },
                                              { 10.5, 5.0 },
                                              { 8.0, 5.0 },
                                              { 8.0, 5.7 },
                                              { 2.8, 5.7 },
                                              { 2.8, 2.0 } },
                                            8.0, 0.03, 5);
  if (people > 0)
  {
    c.obstacles.push_back(walkers(people, 0.25, 0.5));
  }
  return c;
}

}  // namespace fdml_test
