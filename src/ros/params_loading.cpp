// Reading the node's parameters: one typed read per parameter (ParamReader), so a value of the
// wrong type is an error naming the parameter; validate() (params.cpp) checks the ranges.
#include "fdml_localization/ros/param_utils.h"
#include "fdml_localization/ros/params.h"
#include "fdml_localization/ros/reading_buffer.h"

#include <ros/node_handle.h>

#include <cstdlib>
#include <utility>

namespace fdml_localization
{
namespace
{
/// Reads the tracking parameters (core::TrackerOptions, ~global_interval, ~publish_initialpose).
void readTrackingParams(ParamReader& r, Params* p)
{
  core::TrackerOptions& t = p->tracker;
  const std::pair<const char*, double*> reals[] = { { "min_consensus_fraction", &t.min_consensus_fraction },
                                                    { "odom_alpha1", &t.odom_alpha1 },
                                                    { "odom_alpha2", &t.odom_alpha2 },
                                                    { "odom_alpha3", &t.odom_alpha3 },
                                                    { "odom_alpha4", &t.odom_alpha4 },
                                                    { "support_decay", &t.support_decay },
                                                    { "min_support", &t.min_support },
                                                    { "support_margin", &t.support_margin },
                                                    { "tracking_box_min_xy", &t.box_min_xy },
                                                    { "tracking_box_min_theta", &t.box_min_theta },
                                                    { "tracking_box_max_xy", &t.box_max_xy },
                                                    { "tracking_box_max_theta", &t.box_max_theta },
                                                    { "tracking_cell_xy", &t.cell_xy },
                                                    { "tracking_cell_theta", &t.cell_theta },
                                                    { "tracking_merge_distance", &t.merge_distance },
                                                    { "tracking_merge_angle", &t.merge_angle },
                                                    { "publish_max_xy", &t.publish_max_xy },
                                                    { "publish_max_theta", &t.publish_max_theta },
                                                    { "tracking_direction_group", &t.direction_group },
                                                    { "tracking_fix_gate", &t.fix_gate } };
  for (const auto& real : reals)
  {
    r.read(real.first, real.second);
  }
  const std::pair<const char*, int*> integers[] = {
    { "tolerated_misses", &t.tolerated_misses },   { "max_misses", &t.max_misses },
    { "lost_updates", &t.lost_updates },           { "max_hypotheses", &t.max_hypotheses },
    { "tracking_max_seeds", &t.max_seeds },        { "global_interval", &p->global_interval },
    { "conflict_readings", &t.conflict_readings }, { "confirm_searches", &t.confirm_searches },
    { "history_batches", &t.history_batches }
  };
  for (const auto& integer : integers)
  {
    r.read(integer.first, integer.second);
  }
  r.read("publish_initialpose", &p->publish_initialpose);
  r.read("global_deadline", &p->global_deadline);
}

void readMapParams(ParamReader& r, Params* p)
{
  r.read("map_file", &p->map_file);
  r.read("use_map_topic", &p->use_map_topic);
  r.read("map_simplify_tolerance", &p->map_simplify_tolerance);
  r.read("map_min_area", &p->map_min_area);
  r.read("map_seed_point", &p->map_seed_point);
  r.read("map_occupied_threshold", &p->map_occupied_threshold);
  r.read("search_region", &p->search_region);
  r.read("search_region_seed", &p->search_region_seed);
}

void readNodeParams(ParamReader& r, Params* p)
{
  r.read("measurements_per_batch", &p->measurements_per_batch);
  r.read("batch_stride", &p->batch_stride);
  r.read("mode", &p->mode);
  r.read("beams_per_scan", &p->beams_per_scan);
  r.read("transform_tolerance", &p->transform_tolerance);
  r.read("future_tolerance", &p->future_tolerance);
  r.read("max_sensor_frames", &p->max_sensor_frames);
  r.read("relocalize_timeout", &p->relocalize_timeout);
  r.read("publish_tf", &p->publish_tf);
  r.read("tf_publish_rate", &p->tf_publish_rate);
  for (const auto& frame :
       { std::make_pair("global_frame_id", &p->global_frame_id), std::make_pair("odom_frame_id", &p->odom_frame_id),
         std::make_pair("base_frame_id", &p->base_frame_id) })
  {
    if (r.read(frame.first, frame.second))
    {
      *frame.second = tf2FrameId(*frame.second);
    }
  }
  r.read("range_topic", &p->range_topic);
  r.read("scan_topic", &p->scan_topic);
}

void readCoreParams(ParamReader& r, Params* p)
{
  core::LocalizerOptions& o = p->localizer;
  r.read("engine", &p->engine);
  r.read("method", &p->method);
  r.read("no_return", &p->no_return);
  r.read("resolution", &o.resolution);
  r.read("theta_resolution", &o.theta_resolution);
  r.read("min_inliers", &o.min_inliers);
  p->agreement_tolerance_set = r.read("agreement_tolerance", &o.agreement_tolerance);
  r.read("uniqueness_distance", &o.uniqueness_distance);
  r.read("uniqueness_angle", &o.uniqueness_angle);
  p->range_tolerance_set = r.read("range_tolerance", &o.range_tolerance);
  r.read("max_candidates", &o.max_candidates);
  r.read("threads", &o.threads);
  r.read("max_boxes", &o.max_boxes);
  r.read("deadline", &o.deadline);
}
}  // namespace

Params paramsFromTree(const core::ParamValue& tree, const std::string& ros_home, const std::string& home)
{
  Params p;
  ParamReader reader(tree, &p.type_errors);
  readMapParams(reader, &p);
  readNodeParams(reader, &p);
  readCoreParams(reader, &p);
  readTrackingParams(reader, &p);
  p.localizer.cache_dir = defaultCacheDir(expandUser(ros_home, home), home);
  reader.read("cache_dir", &p.localizer.cache_dir);
  p.localizer.cache_dir = expandUser(p.localizer.cache_dir, home);
  return p;
}

Params loadParams(const ros::NodeHandle& nh)
{
  const char* home = std::getenv("HOME");
  const char* ros_home = std::getenv("ROS_HOME");
  return paramsFromTree(readParamTree(nh), ros_home ? ros_home : "", home ? home : "");
}

}  // namespace fdml_localization
