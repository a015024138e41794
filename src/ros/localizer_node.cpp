#include "fdml_localization/ros/localizer_node.h"

#include "fdml_localization/ros/conversions.h"
#include "fdml_localization/ros/node_diagnostics.h"

#include <chrono>
#include <cmath>

namespace fdml_localization
{
namespace
{
/// Batches slide in both modes: the tracker follows every batch after a relocalization.
ReadingBuffer::Options trackingBufferOptions(const Params& params)
{
  ReadingBuffer::Options options = bufferOptions(params);
  options.continuous = true;
  return options;
}
}  // namespace

LocalizerNode::LocalizerNode(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh, const Params& params,
                             const LoadedMap& map)
  : params_(params)
  , nh_(nh)
  , private_nh_(private_nh)
  , service_nh_(private_nh)
  , global_service_nh_(nh)
  , tf_listener_(tf_buffer_)
  , diagnostics_(nh, private_nh)
  , state_(trackingBufferOptions(params_))
  , publisher_(nh_, private_nh_, params_)
  , input_(nh_, params_, state_, tf_buffer_)
{
  const std::string map_topic = nh_.resolveName("map");
  worker_.reset(new SolverWorker(params_, state_, publisher_, map, map_topic));
  state_.have_map = static_cast<bool>(map.map);
  state_.map_source = map.source;
  // Continuous mode localizes from the start; on_request mode waits for a request or a hint.
  state_.relocalizing = solveMode(params_) == SolveMode::Continuous;
  initialpose_sub_ = nh_.subscribe("initialpose", 2, &LocalizerNode::initialPoseCallback, this);
  if (params_.use_map_topic)
  {
    // The callback only stores the message: the worker converts it between two solves.
    map_sub_ = nh_.subscribe("map", 1, &LocalizerNode::mapCallback, this);
    ROS_INFO("fdml_localizer: taking maps from %s%s", map_topic.c_str(), map.map ? "" : " (no map until one arrives)");
  }
  diagnostics_.setHardwareID("fdml_localizer");
  diagnostics_.add("localizer", [this](diagnostic_updater::DiagnosticStatusWrapper& status) {
    std::lock_guard<std::mutex> lock(state_.mutex);
    diagnoseLocked(state_, params_, status);
  });
  service_nh_.setCallbackQueue(&service_queue_);
  global_service_nh_.setCallbackQueue(&service_queue_);
  relocalize_srv_ = service_nh_.advertiseService("relocalize", &LocalizerNode::relocalizeService, this);
  localize_srv_ = service_nh_.advertiseService("localize", &LocalizerNode::localizeService, this);
  global_localization_srv_ =
      global_service_nh_.advertiseService("global_localization", &LocalizerNode::globalLocalizationService, this);
  service_spinner_.reset(new ros::AsyncSpinner(2, &service_queue_));
  service_spinner_->start();
  process_timer_ = nh_.createWallTimer(ros::WallDuration(0.02), &LocalizerNode::processTimer, this);
  status_timer_ = nh_.createWallTimer(ros::WallDuration(0.5), &LocalizerNode::statusTimer, this);
  if (params_.publish_tf)
  {
    tf_timer_ = nh_.createWallTimer(ros::WallDuration(1.0 / params_.tf_publish_rate), &LocalizerNode::tfTimer, this);
  }
  // Last: nothing below can throw, so a started worker is always joined by the destructor.
  worker_->start();
}

LocalizerNode::~LocalizerNode()
{
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    state_.shutting_down = true;
    state_.failAllWaitersLocked("the node is shutting down");
  }
  state_.work_ready.notify_all();
  process_timer_.stop();
  status_timer_.stop();
  tf_timer_.stop();
  worker_.reset();  // joins the worker thread
  service_spinner_->stop();
}

void LocalizerNode::processTimer(const ros::WallTimerEvent& /*event*/)
{
  input_.process();
  diagnostics_.update();
}

void LocalizerNode::statusTimer(const ros::WallTimerEvent& /*event*/)
{
  fdml_localization::Status status;
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    status = state_.statusLocked();
  }
  publisher_.publishStatus(status);
}

void LocalizerNode::initialPoseCallback(const ros::MessageEvent<const geometry_msgs::PoseWithCovarianceStamped>& event)
{
  if (event.getPublisherName() == ros::this_node::getName())
  {
    return;  // our own hand-over (~publish_initialpose)
  }
  const geometry_msgs::PoseWithCovarianceStamped& msg = *event.getConstMessage();
  PoseHint hint;
  hint.pose = fromPoseMsg(msg.pose.pose);
  const int index[3] = { 0, 1, 5 };  // x, y, yaw in the 6 x 6 covariance
  for (int r = 0; r < 3; ++r)
  {
    for (int c = 0; c < 3; ++c)
    {
      hint.covariance(r, c) = msg.pose.covariance[6 * index[r] + index[c]];
    }
  }
  if (!std::isfinite(hint.pose.x) || !std::isfinite(hint.pose.y) || !std::isfinite(hint.pose.theta) ||
      (!msg.header.frame_id.empty() && msg.header.frame_id != params_.global_frame_id))
  {
    ROS_WARN("fdml_localizer: initialpose ignored: a non-finite pose or a frame other than %s (got \"%s\")",
             params_.global_frame_id.c_str(), msg.header.frame_id.c_str());
    return;
  }
  std::lock_guard<std::mutex> lock(state_.mutex);
  state_.pending_hint = hint;
  ROS_INFO("fdml_localizer: initialpose (%.2f, %.2f, %.2f) received: checked against the next batch", hint.pose.x,
           hint.pose.y, hint.pose.theta);
}

void LocalizerNode::tfTimer(const ros::WallTimerEvent& /*event*/)
{
  core::Pose2 map_to_odom;
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    if (!state_.have_map_to_odom)
    {
      return;
    }
    map_to_odom = state_.map_to_odom;
  }
  publisher_.publishMapToOdom(map_to_odom);
}

void LocalizerNode::mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& msg)
{
  // Only store it: the worker converts it and builds the tables (seconds for a large map).
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    ++state_.stats.maps_received;
    if (state_.pending_map)
    {
      ++state_.stats.maps_replaced;
    }
    state_.pending_map = msg;
  }
  state_.work_ready.notify_one();
  ROS_INFO("fdml_localizer: received a %u x %u map at %g m/cell on %s; converting it", msg->info.width,
           msg->info.height, msg->info.resolution, map_sub_.getTopic().c_str());
}

std::string LocalizerNode::refusalLocked() const
{
  if (state_.shutting_down)
  {
    return "the node is shutting down";
  }
  return state_.have_map ? std::string() : worker_->noMapMessage();
}

void LocalizerNode::startRelocalizationLocked(const OutcomePromise& waiter)
{
  // Fresh readings only: a batch formed before the request is stale.
  state_.buffer.clear();
  state_.queued_batches.clear();
  if (waiter)
  {
    state_.relocalize_waiters.push_back(waiter);
  }
  // The robot may have been kidnapped: stop vouching for the old map -> odom, and let no batch
  // formed before this request (perhaps being solved right now) bring it back.
  state_.have_map_to_odom = false;
  state_.relocalizing = true;
  ++state_.generation;
  state_.activity = "relocalizing: waiting for " + std::to_string(params_.measurements_per_batch) + " fresh readings";
  state_.tracking.message = state_.activity;
}

bool LocalizerNode::relocalizeService(fdml_localization::Relocalize::Request& req,
                                      fdml_localization::Relocalize::Response& res)
{
  if (!(req.timeout >= 0.0 && req.timeout <= kMaxRelocalizeTimeout))
  {
    res.success = false;
    res.message = "timeout = " + std::to_string(req.timeout) +
                  " is out of range; allowed: 0 (~relocalize_timeout) or "
                  "(0, 3600] s";
    return true;
  }
  const double timeout = req.timeout > 0.0 ? req.timeout : params_.relocalize_timeout;
  auto waiter = std::make_shared<std::promise<Outcome>>();
  std::future<Outcome> future = waiter->get_future();
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    res.message = refusalLocked();
    if (!res.message.empty())
    {
      res.success = false;
      return true;
    }
    startRelocalizationLocked(waiter);
  }
  ROS_INFO("fdml_localizer: relocalizing: waiting up to %g s until one hypothesis is clearly supported (drive or "
           "rotate the robot, or sweep the sensors)",
           timeout);
  if (future.wait_for(std::chrono::duration<double>(timeout)) != std::future_status::ready)
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    res.success = false;
    res.message = "timed out after " + std::to_string(timeout) + " s: " + state_.tracking.message + "; " +
                  std::to_string(state_.buffer.resolvedCount()) + " readings ready, " +
                  std::to_string(state_.buffer.pendingCount()) +
                  " waiting for tf (publish range/scan readings and tf while the robot drives or rotates in place or "
                  "the sensors sweep; the relocalization goes on: ~pose and map -> odom follow once one hypothesis is "
                  "clearly supported)";
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
    std::lock_guard<std::mutex> lock(state_.mutex);
    res.message = refusalLocked();
    if (!res.message.empty())
    {
      res.success = false;
      return true;
    }
    Job job;
    job.readings = fromReadingMsgs(req.readings);
    job.waiters.push_back(waiter);
    state_.queued_requests.push_back(std::move(job));
  }
  state_.work_ready.notify_one();
  const Outcome outcome = future.get();
  res.success = outcome.success;
  res.message = outcome.message;
  res.result = outcome.result;
  return true;
}

bool LocalizerNode::globalLocalizationService(std_srvs::Empty::Request& /*req*/, std_srvs::Empty::Response& /*res*/)
{
  std::lock_guard<std::mutex> lock(state_.mutex);
  const std::string refusal = refusalLocked();
  if (!refusal.empty())
  {
    ROS_WARN("fdml_localizer: global_localization ignored: %s", refusal.c_str());
    return true;
  }
  startRelocalizationLocked(nullptr);
  ROS_INFO("fdml_localizer: global localization started (drive or rotate the robot, or sweep the sensors)");
  return true;
}

int runLocalizerNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
{
  Params params = loadParams(private_nh);
  const std::vector<std::string> errors = validate(params);
  for (const std::string& error : errors)
  {
    ROS_FATAL("fdml_localizer: invalid parameter: %s", error.c_str());
  }
  if (!errors.empty())
  {
    return 2;
  }
  ROS_INFO_STREAM(describe(params));
  try
  {
    params.search_region_map = loadSearchRegionFile(params.search_region, params.search_region_seed);
    LoadedMap map;
    if (!params.map_file.empty())
    {
      map = loadMapFromFile(params.map_file, toGridOptions(params));
    }
    LocalizerNode node(nh, private_nh, params, map);
    ros::spin();
  }
  catch (const std::exception& error)
  {
    ROS_FATAL("fdml_localizer: %s", error.what());
    return 1;
  }
  return 0;
}

}  // namespace fdml_localization
