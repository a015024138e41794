// The localizer node's solve step and outputs: result, candidates, pose, map -> odom,
// markers and diagnostics.
#include "fdml_localization/ros/localizer_node.h"

#include "fdml_localization/ros/conversions.h"

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace fdml_localization
{
namespace
{
ros::Time stampToTime(std::int64_t stamp)
{
  ros::Time time;
  time.fromNSec(static_cast<std::uint64_t>(stamp));
  return time;
}
}  // namespace

bool isUnambiguous(const core::Result& result)
{
  const auto& candidates = result.candidates;
  return candidates.size() == 1 || (candidates.size() > 1 && candidates[0].inliers > candidates[1].inliers);
}

core::Pose2 carryForward(const core::Pose2& pose, const core::Pose2& base_first, const core::Pose2& base_newest)
{
  return core::compose(pose, core::between(base_first, base_newest));
}

Eigen::Matrix3d carryForwardCovariance(const Eigen::Matrix3d& covariance, const core::Pose2& pose,
                                       const core::Pose2& base_first, const core::Pose2& base_newest)
{
  // q' = q (+) d with d fixed: dq'/dq = [1 0 -s dx - c dy; 0 1 c dx - s dy; 0 0 1].
  const core::Pose2 d = core::between(base_first, base_newest);
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  Eigen::Matrix3d jacobian = Eigen::Matrix3d::Identity();
  jacobian(0, 2) = -s * d.x - c * d.y;
  jacobian(1, 2) = c * d.x - s * d.y;
  return jacobian * covariance * jacobian.transpose();
}

LocalizerNode::Outcome LocalizerNode::solve(const Job& job)
{
  Outcome outcome;
  core::Result result;
  bool solved = false;
  try
  {
    result = localizer_->localize(job.readings);
    solved = true;
  }
  catch (const core::InvalidInput& error)
  {
    outcome.message = std::string("invalid readings: ") + error.what();
  }
  catch (const std::exception& error)
  {
    outcome.message = std::string("the solver failed: ") + error.what();
  }

  outcome.result = toResultMsg(result);
  outcome.result.header.frame_id = params_.global_frame_id;
  outcome.result.header.stamp = job.from_sensors ? stampToTime(job.batch.newest_stamp) : ros::Time::now();
  if (job.from_sensors)
  {
    // Like ~candidates, the result's poses are the robot's at its stamp (the newest reading),
    // not at the batch's first reading where the core expresses them.
    for (std::size_t i = 0; i < result.candidates.size(); ++i)
    {
      outcome.result.candidates[i].pose =
          toPoseMsg(carryForward(result.candidates[i].pose, job.batch.base_first, job.batch.base_newest));
    }
  }
  const bool unambiguous = solved && isUnambiguous(result);
  if (solved)
  {
    outcome.success = !result.candidates.empty();
    char text[256];
    if (result.candidates.empty())
    {
      std::snprintf(text, sizeof(text), "no pose explains at least %d of the %d readings", result.min_inliers_used,
                    result.readings_used);
    }
    else
    {
      std::snprintf(text, sizeof(text), "%zu candidate(s); the best explains %d of %d readings (rms %.3f m), %s",
                    result.candidates.size(), result.candidates[0].inliers, result.readings_used,
                    result.candidates[0].rms_residual, unambiguous ? "unambiguous" : "ambiguous");
    }
    outcome.message = text;
  }

  {
    std::lock_guard<std::mutex> lock(mutex_);
    setDropCounts(buffer_.dropCounts(), &outcome.result);
    if (job.from_sensors)
    {
      ++batches_solved_;
      last_solve_time_ = result.times.total;
      last_candidates_ = static_cast<int>(result.candidates.size());
      last_unambiguous_ = unambiguous;
      if (!solved)
      {
        ++solve_errors_;
        last_error_ = outcome.message;
      }
      if (unambiguous && job.generation == relocalization_generation_)
      {
        have_map_to_odom_ = true;
        map_to_odom_ = core::compose(result.candidates[0].pose, core::inverse(job.batch.base_first));
      }
      state_ = buffer_.batchRequested() ? state_ : (mode_ == SolveMode::Continuous ? "tracking" : "idle");
    }
  }
  if (job.from_sensors)
  {
    publishBatchOutcome(job, result, outcome);
  }
  // Continuous mode solves many batches a second: its per-batch line is a debug message.
  const ros::console::levels::Level level =
      job.from_sensors && mode_ == SolveMode::Continuous ? ros::console::levels::Debug : ros::console::levels::Info;
  ROS_LOG(level, ROSCONSOLE_DEFAULT_NAME, "fdml_localizer: %s: %s (%.3f s)", job.from_sensors ? "batch" : "~localize",
          outcome.message.c_str(), result.times.total);
  return outcome;
}

void LocalizerNode::publishBatchOutcome(const Job& job, const core::Result& result, const Outcome& outcome)
{
  const Batch& batch = job.batch;
  const ros::Time stamp = stampToTime(batch.newest_stamp);
  result_pub_.publish(outcome.result);

  geometry_msgs::PoseArray candidates;
  candidates.header.stamp = stamp;
  candidates.header.frame_id = params_.global_frame_id;
  for (const core::Candidate& candidate : result.candidates)
  {
    candidates.poses.push_back(toPoseMsg(carryForward(candidate.pose, batch.base_first, batch.base_newest)));
  }
  candidates_pub_.publish(candidates);

  if (result.candidates.empty())
  {
    return;
  }
  const core::Candidate& best = result.candidates.front();
  reading_markers_pub_.publish(
      readingMarkers(job.readings, best.pose, best.inlier_mask, params_.global_frame_id, stamp));

  if (!isUnambiguous(result))
  {
    return;
  }
  Eigen::Matrix3d covariance = best.covariance;
  if (!covariance.allFinite() || covariance.diagonal().minCoeff() <= 0.0)
  {
    // No usable covariance from the polish: one grid cell in each direction.
    const core::Vec2 size = map_->map().bounds().size();
    const double cell = std::max(size.x(), size.y()) / std::max(1, params_.resolution);
    const int theta_cells = params_.theta_resolution > 0 ? params_.theta_resolution : params_.resolution;
    covariance = Eigen::Vector3d(cell * cell, cell * cell, std::pow(core::kTwoPi / theta_cells, 2)).asDiagonal();
  }
  geometry_msgs::PoseWithCovarianceStamped pose;
  pose.header = candidates.header;
  pose.pose.pose = candidates.poses.front();
  pose.pose.covariance =
      toCovariance6(carryForwardCovariance(covariance, best.pose, batch.base_first, batch.base_newest));
  pose_pub_.publish(pose);
  if (params_.publish_tf)
  {
    publishMapToOdom(ros::WallTimerEvent());
  }
}

void LocalizerNode::publishMapToOdom(const ros::WallTimerEvent& /*event*/)
{
  core::Pose2 map_to_odom;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!have_map_to_odom_)
    {
      return;
    }
    map_to_odom = map_to_odom_;
  }
  // Future-dated like AMCL, so the transform stays usable until the next one arrives.
  geometry_msgs::TransformStamped transform;
  transform.header.stamp = ros::Time::now() + ros::Duration(params_.transform_tolerance);
  transform.header.frame_id = params_.global_frame_id;
  transform.child_frame_id = params_.odom_frame_id;
  transform.transform = toTransformMsg(map_to_odom);
  tf_broadcaster_.sendTransform(transform);
}

void LocalizerNode::publishMapMarkers()
{
  if (!map_)
  {
    return;
  }
  map_markers_pub_.publish(mapMarkers(map_->map(), params_.global_frame_id, ros::Time::now()));
}

void LocalizerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status)
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (!have_map_)
  {
    status.summary(maps_rejected_ > 0 ? diagnostic_msgs::DiagnosticStatus::ERROR :
                                        diagnostic_msgs::DiagnosticStatus::WARN,
                   maps_rejected_ > 0 ? "no usable map: " + last_map_error_ : std::string("no map yet"));
  }
  else if (last_candidates_ < 0)
  {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "no batch solved yet (" + state_ + ")");
  }
  else if (!last_error_.empty() && last_candidates_ == 0)
  {
    status.summary(diagnostic_msgs::DiagnosticStatus::ERROR, last_error_);
  }
  else if (last_candidates_ == 0)
  {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN, "no pose explains the last batch");
  }
  else if (!last_unambiguous_)
  {
    status.summary(diagnostic_msgs::DiagnosticStatus::WARN,
                   "ambiguous: " + std::to_string(last_candidates_) + " candidates tie on the best inlier count");
  }
  else
  {
    status.summary(diagnostic_msgs::DiagnosticStatus::OK, "localized");
  }
  status.add("state", state_);
  status.add("readings received", buffer_.received());
  status.add("readings dropped", buffer_.dropped());
  for (const auto& drop : buffer_.dropCounts())
  {
    status.add("dropped: " + drop.first, drop.second);
  }
  status.add("readings waiting for tf", buffer_.pendingCount());
  status.add("readings ready", buffer_.resolvedCount());
  status.add("batches solved", batches_solved_);
  status.add("batches replaced before solving", batches_replaced_);
  status.add("solver errors", solve_errors_);
  status.add("last solve time [s]", last_solve_time_);
  status.add("candidates", last_candidates_);
  status.add("map", have_map_ ? map_source_ : std::string("(none yet)"));
  if (params_.use_map_topic)
  {
    status.add("maps received", maps_received_);
    status.add("maps in use", maps_accepted_);
    status.add("maps rejected", maps_rejected_);
    status.add("maps replaced before conversion", maps_replaced_);
    status.add("last map error", last_map_error_);
  }
}

}  // namespace fdml_localization
