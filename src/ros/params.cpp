#include "fdml_localization/ros/params.h"

#include "fdml_localization/ros/param_utils.h"
#include "fdml_localization/ros/reading_buffer.h"
#include "fdml_localization/core/map/grid/grid_tolerances.h"

#include <ros/node_handle.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace fdml_localization
{
namespace
{
std::string quoted(const std::string& text)
{
  return "\"" + text + "\"";
}

/// Appends "~name = value is out of range; allowed: range" when @p ok is false.
template <typename T>
void check(std::vector<std::string>* errors, bool ok, const char* name, const T& value, const std::string& allowed)
{
  if (ok)
  {
    return;
  }
  std::ostringstream out;
  out << "~" << name << " = " << value << " is out of range; allowed: " << allowed;
  errors->push_back(out.str());
}

/// True when @p parse (core::parseEngine, core::parseMethod) accepts @p name.
template <typename Parse>
bool knownName(const std::string& name, Parse parse)
{
  try
  {
    parse(name);
    return true;
  }
  catch (const std::invalid_argument&)
  {
    return false;
  }
}

bool finiteIn(double value, double lo, double hi)
{
  return std::isfinite(value) && value >= lo && value <= hi;
}

/// The parameter of a core::TrackerOptions field: the box options are ~tracking_*.
std::string trackerParameterName(const std::string& option)
{
  const bool box = option.rfind("box_", 0) == 0 || option.rfind("cell_", 0) == 0 || option == "max_seeds" ||
                   option.rfind("merge_", 0) == 0 || option == "direction_group" || option == "fix_gate";
  return (box ? "~tracking_" : "~") + option;
}

bool validFrame(const std::string& frame)
{
  return !frame.empty() && frame.find_first_of(" \t\n") == std::string::npos;
}
}  // namespace

bool parseSolveMode(const std::string& text, SolveMode* mode)
{
  if (text == "on_request")
  {
    *mode = SolveMode::OnRequest;
    return true;
  }
  if (text == "continuous")
  {
    *mode = SolveMode::Continuous;
    return true;
  }
  return false;
}

const char* toString(SolveMode mode)
{
  return mode == SolveMode::Continuous ? "continuous" : "on_request";
}

namespace
{

/// An optional point parameter: empty, or [x, y] of two finite numbers [m].
void checkPoint(std::vector<std::string>* errors, const std::string& name, const std::vector<double>& point,
                const std::string& unset)
{
  if (point.empty() || (point.size() == 2 && std::isfinite(point[0]) && std::isfinite(point[1])))
  {
    return;
  }
  std::ostringstream out;
  out << "~" << name << " = [";
  for (std::size_t i = 0; i < point.size(); ++i)
  {
    out << (i ? ", " : "") << point[i];
  }
  out << "] is out of range; allowed: a list [x, y] of two finite numbers [m] " << unset;
  errors->push_back(out.str());
}

void validateMapParams(const Params& p, std::vector<std::string>* errors)
{
  if (p.map_file.empty() && !p.use_map_topic)
  {
    errors->push_back("~map_file is required unless ~use_map_topic is true: a .poly or map_server .yaml path, "
                      "absolute or package://fdml_localization/maps/...");
  }
  check(errors, finiteIn(p.map_simplify_tolerance, 0.0, 10.0), "map_simplify_tolerance", p.map_simplify_tolerance,
        "0 (one cell) or (0, 10] m");
  check(errors, !std::isnan(p.map_min_area) && p.map_min_area <= 1e6, "map_min_area", p.map_min_area,
        "< 0 (ten cells' area) or [0, 1e6] m^2");
  checkPoint(errors, "map_seed_point", p.map_seed_point, "(or unset: the largest free region)");
  checkPoint(errors, "search_region_seed", p.search_region_seed,
             "(or unset: the largest free region of a grid ~search_region)");
  if (!p.search_region_seed.empty() && p.search_region.empty())
  {
    errors->push_back("~search_region_seed is set without ~search_region; allowed: only with a ~search_region grid");
  }
  check(errors, p.map_occupied_threshold >= 1 && p.map_occupied_threshold <= 100, "map_occupied_threshold",
        p.map_occupied_threshold, "an integer in [1, 100]");
}

void validateInputParams(const Params& p, std::vector<std::string>* errors)
{
  const int k = p.measurements_per_batch;
  check(errors, k >= 3 && k <= 255, "measurements_per_batch", k, "an integer in [3, 255]");
  check(errors, p.batch_stride >= 1 && p.batch_stride <= std::max(k, 1), "batch_stride", p.batch_stride,
        "an integer in [1, ~measurements_per_batch]");
  SolveMode mode;
  check(errors, parseSolveMode(p.mode, &mode), "mode", quoted(p.mode), "\"on_request\" or \"continuous\"");
  check(errors, p.beams_per_scan >= 1 && p.beams_per_scan <= 1000, "beams_per_scan", p.beams_per_scan,
        "an integer in [1, 1000]");
  check(errors, finiteIn(p.transform_tolerance, 0.0, 10.0), "transform_tolerance", p.transform_tolerance, "[0, 10] s");
  check(errors, finiteIn(p.future_tolerance, 0.0, 3600.0), "future_tolerance", p.future_tolerance, "[0, 3600] s");
  check(errors, p.max_sensor_frames >= 1 && p.max_sensor_frames <= 1000000, "max_sensor_frames", p.max_sensor_frames,
        "an integer in [1, 1000000]");
  check(errors, finiteIn(p.relocalize_timeout, 1e-3, 3600.0), "relocalize_timeout", p.relocalize_timeout,
        "(0, 3600] s");
  check(errors, finiteIn(p.tf_publish_rate, 1e-3, 1000.0), "tf_publish_rate", p.tf_publish_rate, "(0, 1000] Hz");
  check(errors, !p.range_topic.empty(), "range_topic", quoted(p.range_topic), "a non-empty topic name");
  check(errors, !p.scan_topic.empty(), "scan_topic", quoted(p.scan_topic), "a non-empty topic name");
}

void validateFrameParams(const Params& p, std::vector<std::string>* errors)
{
  check(errors, validFrame(p.global_frame_id), "global_frame_id", quoted(p.global_frame_id),
        "a non-empty frame id without spaces");
  check(errors, validFrame(p.odom_frame_id), "odom_frame_id", quoted(p.odom_frame_id),
        "a non-empty frame id without spaces");
  check(errors, validFrame(p.base_frame_id), "base_frame_id", quoted(p.base_frame_id),
        "a non-empty frame id without spaces");
  check(errors, p.odom_frame_id != p.base_frame_id && p.odom_frame_id != p.global_frame_id, "odom_frame_id",
        quoted(p.odom_frame_id), "a frame different from ~global_frame_id and ~base_frame_id");
}

void validateCoreParams(const Params& p, std::vector<std::string>* errors)
{
  check(errors, knownName(p.engine, core::parseEngine), "engine", quoted(p.engine),
        "\"voxel\", \"adaptive\" or \"auto\"");
  check(errors, knownName(p.method, core::parseMethod), "method", quoted(p.method),
        "\"robust\", \"paper\" or \"baseline\"");
  check(errors, knownName(p.no_return, core::parseNoReturn), "no_return", quoted(p.no_return),
        "\"constraint\", \"weak\" or \"drop\"");
  check(errors, p.localizer.min_inliers <= p.measurements_per_batch, "min_inliers", p.localizer.min_inliers,
        "0 (automatic) or an integer in [3, ~measurements_per_batch]");
  // The core options: one validation, reported under the parameters' names (k is the batch size).
  const auto parameter = [](const std::string& n) { return n == "k" ? "~measurements_per_batch" : "~" + n; };
  for (const std::string& error : core::validate(toLocalizerOptions(p), parameter))
  {
    errors->push_back(error);
  }
}

void validateTrackingParams(const Params& p, std::vector<std::string>* errors)
{
  // The core's one validation of the tracker options, under the parameters' names.
  for (const std::string& error : core::validate(p.tracker, trackerParameterName))
  {
    errors->push_back(error);
  }
  check(errors, p.global_interval >= 1 && p.global_interval <= 1000000, "global_interval", p.global_interval,
        "an integer in [1, 1000000]");
  check(errors, std::isfinite(p.global_deadline) && p.global_deadline >= 0.0 && p.global_deadline <= 3600.0,
        "global_deadline", p.global_deadline, "[0, 3600] s");
}
}  // namespace

std::vector<std::string> validate(const Params& p)
{
  std::vector<std::string> errors = p.type_errors;
  validateMapParams(p, &errors);
  validateInputParams(p, &errors);
  validateFrameParams(p, &errors);
  validateCoreParams(p, &errors);
  validateTrackingParams(p, &errors);
  return errors;
}

core::LocalizerOptions toLocalizerOptions(const Params& p)
{
  core::LocalizerOptions options = p.localizer;
  // Unknown names keep the defaults; validate() reports them.
  if (knownName(p.engine, core::parseEngine))
  {
    options.engine = core::parseEngine(p.engine);
  }
  if (knownName(p.method, core::parseMethod))
  {
    options.method = core::parseMethod(p.method);
  }
  if (knownName(p.no_return, core::parseNoReturn))
  {
    options.no_return = core::parseNoReturn(p.no_return);
  }
  options.search_region = p.search_region_map;
  return options;
}

core::GridConversionOptions toGridOptions(const Params& p)
{
  core::GridConversionOptions options;
  options.tolerance = p.map_simplify_tolerance;
  options.min_area = p.map_min_area;
  options.use_seed = p.map_seed_point.size() == 2;
  if (options.use_seed)
  {
    options.seed_point = core::Vec2(p.map_seed_point[0], p.map_seed_point[1]);
  }
  options.occupied_threshold = p.map_occupied_threshold;
  return options;
}

Params withGridTolerances(const Params& params, double resolution)
{
  Params p = params;
  p.localizer = core::withGridTolerances(params.localizer, resolution,
                                         { params.range_tolerance_set, params.agreement_tolerance_set });
  return p;
}

SolveMode solveMode(const Params& params)
{
  SolveMode mode = SolveMode::OnRequest;
  parseSolveMode(params.mode, &mode);
  return mode;
}

std::string expandUser(const std::string& path, const std::string& home)
{
  if (path == "~")
  {
    return home;
  }
  if (path.size() >= 2 && path[0] == '~' && path[1] == '/')
  {
    return home + path.substr(1);
  }
  return path;
}

std::string defaultCacheDir(const std::string& ros_home, const std::string& home)
{
  if (!ros_home.empty())
  {
    return ros_home + "/fdml_localization";
  }
  return (home.empty() ? std::string(".") : home) + "/.ros/fdml_localization";
}

std::string describe(const Params& p)
{
  std::ostringstream out;
  out << "fdml_localizer configuration:\n"
      << "  map_file: " << (p.map_file.empty() ? "(none)" : p.map_file)
      << ", use_map_topic: " << (p.use_map_topic ? "true" : "false") << "\n"
      << "  grid maps: map_simplify_tolerance: " << p.map_simplify_tolerance
      << " m (0 = one cell), map_min_area: " << p.map_min_area << " m^2 (< 0 = ten cells), map_seed_point: "
      << (p.map_seed_point.size() == 2 ?
              "[" + std::to_string(p.map_seed_point[0]) + ", " + std::to_string(p.map_seed_point[1]) + "]" :
              std::string("(largest free region)"))
      << ", map_occupied_threshold: " << p.map_occupied_threshold
      << ", search_region: " << (p.search_region.empty() ? std::string("(the whole map)") : p.search_region) << "\n"
      << "  measurements_per_batch: " << p.measurements_per_batch << ", batch_stride: " << p.batch_stride
      << ", mode: " << p.mode << ", beams_per_scan: " << p.beams_per_scan << "\n"
      << "  transform_tolerance: " << p.transform_tolerance << " s, relocalize_timeout: " << p.relocalize_timeout
      << " s, publish_tf: " << (p.publish_tf ? "true" : "false") << " at " << p.tf_publish_rate << " Hz\n"
      << "  frames: global " << p.global_frame_id << ", odom " << p.odom_frame_id << ", base " << p.base_frame_id
      << "\n"
      << "  topics: range " << p.range_topic << ", scan " << p.scan_topic << "\n"
      << "  engine: " << p.engine << ", method: " << p.method << ", no_return: " << p.no_return
      << ", resolution: " << p.localizer.resolution << ", theta_resolution: " << p.localizer.theta_resolution
      << ", min_inliers: " << p.localizer.min_inliers << "\n"
      << "  agreement_tolerance: " << p.localizer.agreement_tolerance << " m"
      << (p.agreement_tolerance_set ? "" : " (default)") << ", uniqueness_distance: " << p.localizer.uniqueness_distance
      << " m, uniqueness_angle: " << p.localizer.uniqueness_angle
      << " rad, range_tolerance: " << p.localizer.range_tolerance << " m" << (p.range_tolerance_set ? "" : " (default)")
      << "\n"
      << "  max_candidates: " << p.localizer.max_candidates << ", threads: " << p.localizer.threads
      << ", max_boxes: " << p.localizer.max_boxes << ", deadline: " << p.localizer.deadline << " s\n"
      << "  cache_dir: " << (p.localizer.cache_dir.empty() ? "(none)" : p.localizer.cache_dir) << "\n"
      << "  tracking: odom_alpha1..4: " << p.tracker.odom_alpha1 << ", " << p.tracker.odom_alpha2 << ", "
      << p.tracker.odom_alpha3 << ", " << p.tracker.odom_alpha4
      << ", min_consensus_fraction: " << p.tracker.min_consensus_fraction << ", min_support: " << p.tracker.min_support
      << ", support_margin: " << p.tracker.support_margin << ", lost_updates: " << p.tracker.lost_updates
      << ", max_hypotheses: " << p.tracker.max_hypotheses << ", confirm_searches: " << p.tracker.confirm_searches
      << ", history_batches: " << p.tracker.history_batches << ", global_interval: " << p.global_interval
      << ", global_deadline: " << p.global_deadline
      << ", publish_initialpose: " << (p.publish_initialpose ? "true" : "false");
  return out.str();
}

}  // namespace fdml_localization
