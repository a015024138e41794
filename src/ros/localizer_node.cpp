#include "fdml_localization/ros/localizer_node.h"

#include "fdml_localization/ros/conversions.h"

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <visualization_msgs/MarkerArray.h>

#include <chrono>
#include <cmath>

namespace fdml_localization
{
namespace
{
ReadingBuffer::Options bufferOptions(const Params& params)
{
  ReadingBuffer::Options options;
  options.batch_size = params.measurements_per_batch;
  options.stride = params.batch_stride;
  options.continuous = solveMode(params) == SolveMode::Continuous;
  options.transform_tolerance = params.transform_tolerance;
  return options;
}
}  // namespace

LocalizerNode::LocalizerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const Params& params,
                             const LoadedMap& map)
  : params_(params)
  , mode_(solveMode(params))
  , map_(map.map)
  , nh_(nh)
  , private_nh_(private_nh)
  , service_nh_(private_nh)
  , global_service_nh_(nh)
  , tf_buffer_()
  , tf_listener_(tf_buffer_)
  , diagnostics_(nh, private_nh)
  , buffer_(bufferOptions(params))
{
  setUpMaps(map);
  service_nh_.setCallbackQueue(&service_queue_);
  global_service_nh_.setCallbackQueue(&service_queue_);

  candidates_pub_ = private_nh_.advertise<geometry_msgs::PoseArray>("candidates", 1, true);
  result_pub_ = private_nh_.advertise<fdml_localization::LocalizationResult>("result", 1, true);
  pose_pub_ = private_nh_.advertise<geometry_msgs::PoseWithCovarianceStamped>("pose", 1, true);
  map_markers_pub_ = private_nh_.advertise<visualization_msgs::MarkerArray>("map_markers", 1, true);
  reading_markers_pub_ = private_nh_.advertise<visualization_msgs::MarkerArray>("reading_markers", 1, true);
  publishMapMarkers();

  diagnostics_.setHardwareID("fdml_localizer");
  diagnostics_.add("localizer", this, &LocalizerNode::diagnose);

  range_sub_ = nh_.subscribe(params_.range_topic, 100, &LocalizerNode::rangeCallback, this);
  scan_sub_ = nh_.subscribe(params_.scan_topic, 10, &LocalizerNode::scanCallback, this);

  process_timer_ = nh_.createWallTimer(ros::WallDuration(0.02), &LocalizerNode::processTimer, this);
  if (params_.publish_tf)
  {
    tf_timer_ =
        nh_.createWallTimer(ros::WallDuration(1.0 / params_.tf_publish_rate), &LocalizerNode::publishMapToOdom, this);
  }

  relocalize_srv_ = service_nh_.advertiseService("relocalize", &LocalizerNode::relocalizeService, this);
  localize_srv_ = service_nh_.advertiseService("localize", &LocalizerNode::localizeService, this);
  global_localization_srv_ =
      global_service_nh_.advertiseService("global_localization", &LocalizerNode::globalLocalizationService, this);
  service_spinner_.reset(new ros::AsyncSpinner(2, &service_queue_));
  service_spinner_->start();

  // Last: nothing below can throw, so a started worker is always joined by the destructor.
  worker_ = std::thread(&LocalizerNode::workerLoop, this);
}

LocalizerNode::~LocalizerNode()
{
  {
    std::lock_guard<std::mutex> lock(mutex_);
    shutting_down_ = true;
    Outcome stopped;
    stopped.message = "the node is shutting down";
    for (const OutcomePromise& waiter : relocalize_waiters_)
    {
      waiter->set_value(stopped);
    }
    relocalize_waiters_.clear();
    for (Job& job : queued_requests_)
    {
      for (const OutcomePromise& waiter : job.waiters)
      {
        waiter->set_value(stopped);
      }
    }
    queued_requests_.clear();
    if (queued_batch_)
    {
      for (const OutcomePromise& waiter : queued_batch_->waiters)
      {
        waiter->set_value(stopped);
      }
      queued_batch_.reset();
    }
  }
  work_ready_.notify_all();
  process_timer_.stop();
  tf_timer_.stop();
  if (worker_.joinable())
  {
    worker_.join();
  }
  service_spinner_->stop();
}

// ---------------------------------------------------------------------------------------------
// Inputs: callbacks only check and buffer.
// ---------------------------------------------------------------------------------------------

void LocalizerNode::rangeCallback(const sensor_msgs::Range::ConstPtr& msg)
{
  TimedReading reading;
  std::string reason;
  const bool usable = rangeToReading(*msg, ros::Time::now().toSec(), &reading, &reason);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    buffer_.countReceived();
    if (usable)
    {
      buffer_.add(reading, &reason);
    }
    else
    {
      buffer_.countDrop(reason);
    }
  }
  if (!reason.empty())
  {
    ROS_WARN_THROTTLE(5.0, "fdml_localizer: dropped a Range reading from frame \"%s\" (range %g, stamp %.3f): %s",
                      msg->header.frame_id.c_str(), msg->range, msg->header.stamp.toSec(), reason.c_str());
  }
}

void LocalizerNode::scanCallback(const sensor_msgs::LaserScan::ConstPtr& msg)
{
  std::map<std::string, std::uint64_t> drops;
  const std::vector<TimedReading> readings =
      scanToReadings(*msg, params_.beams_per_scan, ros::Time::now().toSec(), &drops);
  std::string reason;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    buffer_.countReceived(msg->ranges.size());
    for (const auto& drop : drops)
    {
      buffer_.countDrop(drop.first, drop.second);
    }
    for (const TimedReading& reading : readings)
    {
      buffer_.add(reading, &reason);
    }
  }
  if (!reason.empty())
  {
    ROS_WARN_THROTTLE(5.0, "fdml_localizer: dropped LaserScan beams from frame \"%s\": %s",
                      msg->header.frame_id.c_str(), reason.c_str());
  }
}

LookupStatus LocalizerNode::lookupInOdom(const std::string& frame, std::int64_t stamp, core::Pose2* pose) const
{
  ros::Time time;
  time.fromNSec(static_cast<std::uint64_t>(stamp));
  try
  {
    if (!tf_buffer_.canTransform(params_.odom_frame_id, frame, time))
    {
      return tf_buffer_._frameExists(frame) ? LookupStatus::NotYet : LookupStatus::UnknownFrame;
    }
    *pose = fromTransformMsg(tf_buffer_.lookupTransform(params_.odom_frame_id, frame, time).transform);
    return LookupStatus::Ok;
  }
  catch (const tf2::TransformException&)
  {
    return LookupStatus::NotYet;
  }
}

void LocalizerNode::warnDropped(const std::string& frame, const std::string& reason)
{
  ROS_WARN_THROTTLE(5.0,
                    "fdml_localizer: dropped a reading from frame \"%s\": %s (no tf %s -> %s and %s -> %s at its "
                    "stamp within ~transform_tolerance = %g s)",
                    frame.c_str(), reason.c_str(), params_.odom_frame_id.c_str(), params_.base_frame_id.c_str(),
                    params_.odom_frame_id.c_str(), frame.c_str(), params_.transform_tolerance);
}

void LocalizerNode::processTimer(const ros::WallTimerEvent& /*event*/)
{
  std::vector<std::pair<TimedReading, std::string>> dropped;
  bool queued = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const auto lookup = [this](const std::string& frame, std::int64_t stamp, core::Pose2* pose) {
      return lookupInOdom(frame, stamp, pose);
    };
    dropped = buffer_.resolve(ros::Time::now().toSec(), params_.base_frame_id, lookup);
    Batch batch;
    while (buffer_.takeBatch(&batch))
    {
      std::unique_ptr<Job> job(new Job);
      job->from_sensors = true;
      job->generation = relocalization_generation_;
      job->readings = batch.readings;
      job->batch = std::move(batch);
      job->waiters.swap(relocalize_waiters_);
      if (queued_batch_)
      {
        // A newer batch replaces the queued one and inherits its waiters.
        ++batches_replaced_;
        job->waiters.insert(job->waiters.end(), queued_batch_->waiters.begin(), queued_batch_->waiters.end());
      }
      queued_batch_ = std::move(job);
      queued = true;
    }
  }
  for (const auto& drop : dropped)
  {
    warnDropped(drop.first.frame_id, drop.second);
  }
  if (queued)
  {
    work_ready_.notify_one();
  }
  diagnostics_.update();
}

// ---------------------------------------------------------------------------------------------
// Services.
// ---------------------------------------------------------------------------------------------

void LocalizerNode::startRelocalizationLocked(const OutcomePromise& waiter)
{
  if (mode_ == SolveMode::OnRequest)
  {
    buffer_.requestBatch();
  }
  else
  {
    buffer_.clear();
  }
  if (queued_batch_)
  {
    // A batch formed before the request is stale: its waiters move on to the fresh batch.
    relocalize_waiters_.insert(relocalize_waiters_.end(), queued_batch_->waiters.begin(), queued_batch_->waiters.end());
    queued_batch_.reset();
  }
  if (waiter)
  {
    relocalize_waiters_.push_back(waiter);
  }
  // The robot may have been kidnapped: stop vouching for the old map -> odom, and let no batch
  // formed before this request (perhaps being solved right now) bring it back.
  have_map_to_odom_ = false;
  ++relocalization_generation_;
  state_ = "relocalizing: waiting for " + std::to_string(params_.measurements_per_batch) + " fresh readings";
}

bool LocalizerNode::relocalizeService(fdml_localization::Relocalize::Request& req,
                                      fdml_localization::Relocalize::Response& res)
{
  const double timeout = req.timeout > 0.0 && std::isfinite(req.timeout) ? req.timeout : params_.relocalize_timeout;
  auto waiter = std::make_shared<std::promise<Outcome>>();
  std::future<Outcome> future = waiter->get_future();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutting_down_ || !have_map_)
    {
      res.success = false;
      res.message = shutting_down_ ? "the node is shutting down" : noMapMessage();
      return true;
    }
    startRelocalizationLocked(waiter);
  }
  ROS_INFO("fdml_localizer: relocalizing: waiting up to %g s for %d fresh readings (rotate the robot in place or "
           "sweep the sensors)",
           timeout, params_.measurements_per_batch);
  if (future.wait_for(std::chrono::duration<double>(timeout)) != std::future_status::ready)
  {
    std::size_t resolved = 0;
    std::size_t pending = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      resolved = buffer_.resolvedCount();
      pending = buffer_.pendingCount();
    }
    res.success = false;
    res.message = "timed out after " + std::to_string(timeout) + " s: " + std::to_string(resolved) + " of " +
                  std::to_string(params_.measurements_per_batch) + " readings ready, " + std::to_string(pending) +
                  " waiting for tf (publish range/scan readings and tf while the robot rotates in place or the "
                  "sensors sweep; the result will still be published on ~result when the batch completes)";
    return true;
  }
  const Outcome outcome = future.get();
  res.success = outcome.success;
  res.message = outcome.message;
  res.result = outcome.result;
  return true;
}

bool LocalizerNode::localizeService(fdml_localization::Localize::Request& req,
                                    fdml_localization::Localize::Response& res)
{
  auto waiter = std::make_shared<std::promise<Outcome>>();
  std::future<Outcome> future = waiter->get_future();
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (shutting_down_ || !have_map_)
    {
      res.success = false;
      res.message = shutting_down_ ? "the node is shutting down" : noMapMessage();
      return true;
    }
    Job job;
    job.readings = fromReadingMsgs(req.readings);
    job.waiters.push_back(waiter);
    queued_requests_.push_back(std::move(job));
  }
  work_ready_.notify_one();
  const Outcome outcome = future.get();
  res.success = outcome.success;
  res.message = outcome.message;
  res.result = outcome.result;
  return true;
}

bool LocalizerNode::globalLocalizationService(std_srvs::Empty::Request& /*req*/, std_srvs::Empty::Response& /*res*/)
{
  std::lock_guard<std::mutex> lock(mutex_);
  if (!have_map_)
  {
    ROS_WARN("fdml_localizer: global_localization ignored: %s", noMapMessage().c_str());
    return true;
  }
  startRelocalizationLocked(nullptr);
  ROS_INFO("fdml_localizer: global localization started: waiting for %d fresh readings (rotate the robot in place "
           "or sweep the sensors)",
           params_.measurements_per_batch);
  return true;
}

// ---------------------------------------------------------------------------------------------
// Worker: owns the core localizer.
// ---------------------------------------------------------------------------------------------

void LocalizerNode::workerLoop()
{
  if (localizer_)
  {
    try
    {
      const auto start = std::chrono::steady_clock::now();
      localizer_->prepare();
      ROS_INFO("fdml_localizer: localizer ready (%s engine, tables in %.2f s)", params_.engine.c_str(),
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    catch (const std::exception& error)
    {
      ROS_ERROR("fdml_localizer: preparing the localizer failed: %s", error.what());
    }
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = localizer_ ? "idle" : "waiting for a map";
  }
  while (true)
  {
    Job job;
    nav_msgs::OccupancyGrid::ConstPtr map;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      work_ready_.wait(lock,
                       [this] { return shutting_down_ || pending_map_ || queued_batch_ || !queued_requests_.empty(); });
      if (shutting_down_)
      {
        return;
      }
      if (pending_map_)
      {
        // A new map goes first: every solve after it uses it.
        map.swap(pending_map_);
        state_ = "converting a map from " + map_sub_.getTopic();
      }
      else if (!queued_requests_.empty())
      {
        job = std::move(queued_requests_.front());
        queued_requests_.pop_front();
      }
      else
      {
        job = std::move(*queued_batch_);
        queued_batch_.reset();
        state_ = "solving a batch";
      }
    }
    if (map)
    {
      applyMap(map);
      continue;
    }
    Outcome outcome;
    if (localizer_)
    {
      outcome = solve(job);
    }
    else
    {
      outcome.message = noMapMessage();
    }
    for (const OutcomePromise& waiter : job.waiters)
    {
      waiter->set_value(outcome);
    }
  }
}

}  // namespace fdml_localization
