#include "fdml_localization/ros/solver_worker.h"

#include "fdml_localization/core/localization/voxel/table_cache.h"

#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/util/stopwatch.h"
#include "fdml_localization/ros/conversions.h"

#include <ros/ros.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <utility>

namespace fdml_localization
{
SolverWorker::SolverWorker(const Params& params, NodeState& state, ResultPublisher& publisher, const LoadedMap& map,
                           std::string map_topic)
  : params_(params), state_(state), publisher_(publisher), map_topic_(std::move(map_topic)), map_(map.map)
{
  if (map.map)
  {
    if (!map.summary.empty())
    {
      ROS_INFO("fdml_localizer: map converted from %s", map.summary.c_str());
    }
    const core::LocalizerOptions options = optionsFor(map);
    localizer_.reset(new core::Localizer(map.map, options));
    global_localizer_ = globalLocalizerFor(map.map, options);
    tracker_ = trackerFor(map.map, options);
    publisher_.publishMapMarkers(*map_);
  }
}

SolverWorker::~SolverWorker()
{
  if (thread_.joinable())
  {
    thread_.join();
  }
  global_search_.reset();
  waitForTables();
}

std::unique_ptr<core::Localizer> SolverWorker::globalLocalizerFor(const std::shared_ptr<const core::MapRayCaster>& map,
                                                                  core::LocalizerOptions options) const
{
  options.engine = core::Engine::Adaptive;
  options.deadline = params_.global_deadline;
  return std::make_unique<core::Localizer>(map, options);
}

void SolverWorker::prepareInBackground()
{
  table_thread_ = std::thread([this] {
    try
    {
      const auto start = std::chrono::steady_clock::now();
      localizer_->prepare();
      ROS_INFO("fdml_localizer: ~localize ready (%s engine, tables in %.2f s)", params_.engine.c_str(),
               core::secondsSince(start));
      warnCacheOnce(*localizer_);
    }
    catch (const std::exception& error)
    {
      ROS_ERROR("fdml_localizer: preparing the localizer failed: %s", error.what());
    }
  });
}

void SolverWorker::waitForTables()
{
  if (table_thread_.joinable())
  {
    table_thread_.join();
  }
}

void SolverWorker::start()
{
  thread_ = std::thread(&SolverWorker::loop, this);
}

std::string SolverWorker::noMapMessage() const
{
  return "no map yet: waiting for a nav_msgs/OccupancyGrid on " + map_topic_ +
         " (~use_map_topic is true and no ~map_file was given)";
}

void SolverWorker::warnCacheOnce(core::Localizer& localizer)
{
  const std::string warning = core::tableCacheWarning(localizer);
  if (!warning.empty() && !cache_warned_)
  {
    ROS_WARN("fdml_localizer: distance-table cache: %s (the tables are built without it)", warning.c_str());
    cache_warned_ = true;
  }
}

void SolverWorker::loop()
{
  if (localizer_)
  {
    // Tracking starts at once (its global searches need no table); ~localize waits for these.
    prepareInBackground();
  }
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    state_.activity = localizer_ ? "idle" : "waiting for a map";
  }
  Job job;
  nav_msgs::OccupancyGrid::ConstPtr map;
  while (takeWork(&job, &map))
  {
    if (map)
    {
      applyMap(map);
      map.reset();
      continue;
    }
    Outcome outcome;
    outcome.message = noMapMessage();
    if (localizer_)
    {
      outcome = job.from_sensors ? trackBatch(job) : solve(job);
    }
    for (const OutcomePromise& waiter : job.waiters)
    {
      waiter->set_value(outcome);
    }
  }
}

bool SolverWorker::takeWork(Job* job, nav_msgs::OccupancyGrid::ConstPtr* map)
{
  std::unique_lock<std::mutex> lock(state_.mutex);
  state_.work_ready.wait(lock, [this] {
    return state_.shutting_down || state_.pending_map || !state_.queued_batches.empty() ||
           !state_.queued_requests.empty();
  });
  if (state_.shutting_down)
  {
    return false;
  }
  if (state_.pending_map)
  {
    // A new map goes first: every solve after it uses it.
    map->swap(state_.pending_map);
    state_.activity = "converting a map from " + map_topic_;
  }
  else if (!state_.queued_requests.empty())
  {
    *job = std::move(state_.queued_requests.front());
    state_.queued_requests.pop_front();
  }
  else
  {
    *job = std::move(state_.queued_batches.front());
    state_.queued_batches.pop_front();
    state_.activity = "solving a batch";
  }
  return true;
}

Outcome SolverWorker::solve(const Job& job)
{
  Outcome outcome;
  core::Result result;
  try
  {
    waitForTables();
    result = localizer_->localize(job.readings);
    outcome.success = !result.candidates.empty();
    outcome.message = describeOutcome(result, core::isUnambiguous(result));
  }
  catch (const std::exception& error)
  {
    const bool invalid = dynamic_cast<const core::InvalidInput*>(&error) != nullptr;
    outcome.message = std::string(invalid ? "invalid readings: " : "the solver failed: ") + error.what();
  }
  outcome.result = resultMessage(job, result);
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    setDropCounts(state_.buffer.dropCounts(), &outcome.result);
  }
  ROS_INFO("fdml_localizer: ~localize: %s (%.3f s)", outcome.message.c_str(), result.times.total);
  return outcome;
}

fdml_localization::LocalizationResult SolverWorker::resultMessage(const Job& job, const core::Result& result) const
{
  fdml_localization::LocalizationResult msg = toResultMsg(result);
  msg.header.frame_id = params_.global_frame_id;
  msg.header.stamp = job.from_sensors ? stampToTime(job.batch.newest_stamp) : ros::Time::now();
  if (job.from_sensors)
  {
    // Like ~candidates, the result's poses are the robot's at its stamp (the newest reading).
    for (std::size_t i = 0; i < result.candidates.size(); ++i)
    {
      msg.candidates[i].pose =
          toPoseMsg(carryForward(result.candidates[i].pose, job.batch.base_first, job.batch.base_newest));
    }
  }
  return msg;
}

std::string SolverWorker::describeOutcome(const core::Result& result, bool unambiguous)
{
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
  return text;
}

core::LocalizerOptions SolverWorker::optionsFor(const LoadedMap& map) const
{
  if (!(map.grid_resolution > 0.0))
  {
    return toLocalizerOptions(params_);
  }
  const Params effective = withGridTolerances(params_, map.grid_resolution);
  ROS_INFO("fdml_localizer: map from a %g m grid: range_tolerance %g m%s, agreement_tolerance %g m%s",
           map.grid_resolution, effective.localizer.range_tolerance,
           params_.range_tolerance_set ? " (as set)" : " (default raised to about a cell)",
           effective.localizer.agreement_tolerance,
           params_.agreement_tolerance_set ? " (as set)" : " (default raised to about two cells)");
  return toLocalizerOptions(effective);
}

std::unique_ptr<core::HypothesisTracker> SolverWorker::trackerFor(const std::shared_ptr<const core::MapRayCaster>& map,
                                                                  const core::LocalizerOptions& options) const
{
  core::TrackerOptions tracker = params_.tracker;
  tracker.agreement_tolerance = options.agreement_tolerance;
  tracker.range_tolerance = options.range_tolerance;
  // Successive batches share k - stride readings: each fix counts stride / k of a new one.
  tracker.fix_covariance_scale =
      static_cast<double>(params_.measurements_per_batch) / std::max(1, params_.batch_stride);
  return std::make_unique<core::HypothesisTracker>(map, tracker);
}

void SolverWorker::applyMap(const nav_msgs::OccupancyGrid::ConstPtr& msg)
{
  waitForTables();         // the build in progress uses localizer_ (and cache_warned_)
  global_search_.reset();  // waits for a global search in progress (it uses global_localizer_)
  const std::string source = "topic " + map_topic_;
  const auto start = std::chrono::steady_clock::now();
  std::shared_ptr<const core::MapRayCaster> map;
  std::unique_ptr<core::Localizer> localizer;
  std::unique_ptr<core::Localizer> global;
  std::unique_ptr<core::HypothesisTracker> tracker;
  std::string error;
  try
  {
    const LoadedMap loaded = mapFromGrid(fromOccupancyGridMsg(*msg), toGridOptions(params_), source);
    ROS_INFO("fdml_localizer: map converted from %s: %s", source.c_str(), loaded.summary.c_str());
    const core::LocalizerOptions options = optionsFor(loaded);
    localizer.reset(new core::Localizer(loaded.map, options));
    localizer->prepare();
    global = globalLocalizerFor(loaded.map, options);
    warnCacheOnce(*localizer);
    tracker = trackerFor(loaded.map, options);
    map = loaded.map;
  }
  catch (const std::exception& exception)
  {
    error = exception.what();
  }
  std::unique_lock<std::mutex> lock(state_.mutex);
  if (!map)
  {
    // The error names the source (the topic).
    ROS_ERROR_THROTTLE(10.0, "fdml_localizer: rejected a %u x %u map at %g m/cell: %s; %s", msg->info.width,
                       msg->info.height, msg->info.resolution, error.c_str(),
                       localizer_ ? "the previous map stays in use" : "still no map");
    ++state_.stats.maps_rejected;
    state_.stats.last_map_error = error;
    state_.activity = localizer_ ? "idle" : "waiting for a map";
    return;
  }
  // Between two solves: the next one uses the new map.
  map_ = map;
  localizer_ = std::move(localizer);
  global_localizer_ = std::move(global);
  if (tracker_)
  {
    // A map of the same frame (a SLAM map growing): the hypotheses carry over.
    tracker->restore(tracker_->hypotheses());
  }
  tracker_ = std::move(tracker);
  ROS_INFO("fdml_localizer: new map in use (%s engine, conversion and tables in %.2f s)", params_.engine.c_str(),
           core::secondsSince(start));
  ++state_.stats.maps_accepted;
  state_.have_map = true;
  state_.map_source = source;
  state_.activity = "idle";
  lock.unlock();
  publisher_.publishMapMarkers(*map_);
}

}  // namespace fdml_localization
