// The localizer node's maps: the map topic (store on arrival, convert in the worker), the
// tolerances of converted grids, and the swap of map and localizer between two solves.
#include "fdml_localization/ros/localizer_node.h"

#include "fdml_localization/ros/conversions.h"

#include <chrono>

namespace fdml_localization
{
void LocalizerNode::setUpMaps(const LoadedMap& map)
{
  if (map.map)
  {
    if (!map.summary.empty())
    {
      ROS_INFO("fdml_localizer: map converted from %s", map.summary.c_str());
    }
    localizer_.reset(new core::Localizer(map.map, optionsFor(map)));
    have_map_ = true;
    map_source_ = map.source;
  }
  if (params_.use_map_topic)
  {
    // The callback only stores the message: nothing else runs before the worker starts.
    map_sub_ = nh_.subscribe("map", 1, &LocalizerNode::mapCallback, this);
    ROS_INFO("fdml_localizer: taking maps from %s%s", map_sub_.getTopic().c_str(),
             map.map ? "" : " (no map until one arrives)");
  }
}

void LocalizerNode::mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& msg)
{
  // Only store it: the worker converts it and builds the tables (seconds for a large map).
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++maps_received_;
    if (pending_map_)
    {
      ++maps_replaced_;
    }
    pending_map_ = msg;
  }
  work_ready_.notify_one();
  ROS_INFO("fdml_localizer: received a %u x %u map at %g m/cell on %s; converting it", msg->info.width,
           msg->info.height, msg->info.resolution, map_sub_.getTopic().c_str());
}

core::LocalizerOptions LocalizerNode::optionsFor(const LoadedMap& map) const
{
  if (!(map.grid_resolution > 0.0))
  {
    return toLocalizerOptions(params_);
  }
  const Params effective = withGridTolerances(params_, map.grid_resolution);
  ROS_INFO("fdml_localizer: map from a %g m grid: range_tolerance %g m%s, agreement_tolerance %g m%s",
           map.grid_resolution, effective.range_tolerance,
           params_.range_tolerance_set ? " (as set)" : " (default raised to about a cell)",
           effective.agreement_tolerance,
           params_.agreement_tolerance_set ? " (as set)" : " (default raised to about two cells)");
  return toLocalizerOptions(effective);
}

std::string LocalizerNode::noMapMessage() const
{
  return "no map yet: waiting for a nav_msgs/OccupancyGrid on " + map_sub_.getTopic() +
         " (~use_map_topic is true and no ~map_file was given)";
}

void LocalizerNode::applyMap(const nav_msgs::OccupancyGrid::ConstPtr& msg)
{
  const std::string source = "topic " + map_sub_.getTopic();
  const auto start = std::chrono::steady_clock::now();
  std::shared_ptr<const core::MapRayCaster> map;
  std::unique_ptr<core::Localizer> localizer;
  std::string error;
  try
  {
    const LoadedMap loaded = mapFromGrid(fromOccupancyGridMsg(*msg), toGridOptions(params_), source);
    ROS_INFO("fdml_localizer: map converted from %s: %s", source.c_str(), loaded.summary.c_str());
    localizer.reset(new core::Localizer(loaded.map, optionsFor(loaded)));
    localizer->prepare();
    map = loaded.map;
  }
  catch (const std::exception& exception)
  {
    error = exception.what();
  }

  if (!map)
  {
    // The error names the source (the topic).
    ROS_ERROR_THROTTLE(10.0, "fdml_localizer: rejected a %u x %u map at %g m/cell: %s; %s", msg->info.width,
                       msg->info.height, msg->info.resolution, error.c_str(),
                       localizer_ ? "the previous map stays in use" : "still no map");
    std::lock_guard<std::mutex> lock(mutex_);
    ++maps_rejected_;
    last_map_error_ = error;
    state_ = localizer_ ? "idle" : "waiting for a map";
    return;
  }
  // Between two solves: the next one uses the new map.
  map_ = map;
  localizer_ = std::move(localizer);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ROS_INFO("fdml_localizer: new map in use (%s engine, conversion and tables in %.2f s)", params_.engine.c_str(),
           seconds);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++maps_accepted_;
    have_map_ = true;
    map_source_ = source;
    state_ = "idle";
  }
  publishMapMarkers();
}

}  // namespace fdml_localization
