/**
 * @file params.h
 * @brief Every parameter of the fdml_localizer node in one struct, its validation (pure, no ROS)
 *        and its loading from the private node handle (thin).
 */
#pragma once

#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/util/param_tree.h"
#include "fdml_localization/core/tracking/hypothesis_tracker.h"

#include <string>
#include <vector>

namespace ros
{
class NodeHandle;
}

namespace fdml_localization
{
/// When the node solves.
enum class SolveMode
{
  OnRequest,  ///< after a ~relocalize or global_localization request, one batch per request
  Continuous  ///< every batch, sliding by ~batch_stride readings
};

/// Parses "on_request" / "continuous"; returns false for anything else.
bool parseSolveMode(const std::string& text, SolveMode* mode);
const char* toString(SolveMode mode);

/// The node's parameters (private namespace, names as in the issue). Defaults are AMCL-like.
struct Params
{
  // Map and batching.
  /// ~map_file: a .poly file or a map_server .yaml, absolute, file://... or package://...;
  /// required unless use_map_topic (then optional: the map used until one arrives on the topic)
  std::string map_file;
  bool use_map_topic = false;  ///< ~use_map_topic: take nav_msgs/OccupancyGrid maps from `map`

  // Occupancy grid -> polygon conversion (a .yaml ~map_file or the map topic).
  double map_simplify_tolerance = 0.0;  ///< ~map_simplify_tolerance [m]: 0 = one cell, else (0, 10]
  double map_min_area = -1.0;           ///< ~map_min_area [m^2]: obstacles smaller are specks; < 0 = ten cells
  /// ~map_seed_point [m]: [x, y] in the map frame, keep the free region holding it; empty =
  /// the largest free region. A list of another length is kept here as given (validate() reports it).
  std::vector<double> map_seed_point;
  int map_occupied_threshold = 50;  ///< ~map_occupied_threshold: cells >= this are walls, [1, 100]
  /// ~search_region: where the robot's base may be, any map file as for ~map_file (its free
  /// space); empty = the whole map. Global searches cover only it (LocalizerOptions::search_region).
  std::string search_region;
  /// ~search_region_seed [m]: [x, y], a grid ~search_region's free region holding it; empty = the largest.
  std::vector<double> search_region_seed;
  /// The region loaded from ~search_region (by runLocalizerNode(), after validation); null = none.
  std::shared_ptr<const core::MapRayCaster> search_region_map;
  int measurements_per_batch = 10;   ///< ~measurements_per_batch: k, in [3, 255]
  int batch_stride = 1;              ///< ~batch_stride: readings the window slides by, in [1, k]
  std::string mode = "on_request";   ///< ~mode: on_request | continuous
  int beams_per_scan = 10;           ///< ~beams_per_scan: readings taken from a LaserScan, [1, 1000]
  double transform_tolerance = 0.1;  ///< ~transform_tolerance [s]: tf wait and tf future-dating, [0, 10]
  /// ~future_tolerance [s]: readings stamped further ahead of the node's clock are dropped
  /// (drop reason future_stamp), [0, 3600]
  double future_tolerance = 0.5;
  /// ~max_sensor_frames: sensor frames whose newest stamp is remembered (least recently seen
  /// forgotten beyond), [1, 1000000]
  int max_sensor_frames = 1024;
  double relocalize_timeout = 30.0;  ///< ~relocalize_timeout [s]: default ~relocalize wait, (0, 3600]
  bool publish_tf = false;           ///< ~publish_tf: publish map -> odom for an unambiguous best
  double tf_publish_rate = 10.0;     ///< ~tf_publish_rate [Hz]: map -> odom republish rate, (0, 1000]

  // Frames (AMCL names).
  std::string global_frame_id = "map";
  std::string odom_frame_id = "odom";
  std::string base_frame_id = "base_link";

  // Input topics (relative names, resolved in the node's namespace, remappable).
  std::string range_topic = "range";
  std::string scan_topic = "scan";

  // Core options: the parameters of the same names (~resolution, ~agreement_tolerance, ...) map
  // onto core::LocalizerOptions, validated once by core::validate(); only the engine and method
  // names are kept as text here, so that an unknown name can be reported.
  std::string engine = "auto";           ///< ~engine: voxel | adaptive | auto
  std::string method = "robust";         ///< ~method: robust | paper | baseline
  std::string no_return = "constraint";  ///< ~no_return: constraint | weak | drop (core NoReturnPolicy)
  core::LocalizerOptions localizer;      ///< every other core option (engine, method: see above)
  bool agreement_tolerance_set = false;  ///< the user set ~agreement_tolerance (see withGridTolerances())
  bool range_tolerance_set = false;      ///< the user set ~range_tolerance (see withGridTolerances())

  /// Parameters set with the wrong type (ParamReader messages; validate() reports them first).
  std::vector<std::string> type_errors;
  // Tracking (docs/localizer_node.md#tracking): ~odom_alpha1..4, ~min_consensus_fraction,
  // ~support_decay, ~min_support, ~support_margin, ~tolerated_misses, ~conflict_readings,
  // ~publish_max_xy, ~publish_max_theta, ~max_misses, ~lost_updates, ~max_hypotheses and the
  // ~tracking_* options (box, cell, merge, direction_group, fix_gate) map onto core::TrackerOptions,
  // validated by core::validate() (its tolerances are the localizer's).
  core::TrackerOptions tracker;
  /// ~global_interval: updates in a row without any fix before another global search, [1, 1e6]
  int global_interval = 40;
  /// ~global_deadline [s]: wall-time budget of each tracking global search (the adaptive engine,
  /// whatever ~engine is; it runs beside the tracking), [0, 3600]; 0 = none. A search cut short
  /// seeds nothing.
  double global_deadline = 0.0;
  bool publish_initialpose =
      false;  ///< ~publish_initialpose: the first clear fix after a relocalization on initialpose
};

/// Largest ~relocalize timeout [s] (a larger or non-finite request is refused).
constexpr double kMaxRelocalizeTimeout = 3600.0;

/**
 * @brief Every problem with @p params, each naming the parameter (with its "~") and its allowed
 *        range. Node-level parameters are checked here; the core options are checked by
 *        core::validate() on toLocalizerOptions(). Empty when the parameters are usable.
 */
std::vector<std::string> validate(const Params& params);

/// The core options from the parameters. Unknown engine/method names fall back to the defaults
/// (validate() reports them).
core::LocalizerOptions toLocalizerOptions(const Params& params);

/// The grid conversion options from the ~map_* parameters.
core::GridConversionOptions toGridOptions(const Params& params);

/**
 * @brief The parameters to use with a map converted from an occupancy grid of cells of
 *        @p resolution [m]: the walls of such a map are only good to about a cell, so a
 *        ~range_tolerance the user did not set becomes max(its default, resolution) and an
 *        ~agreement_tolerance the user did not set max(its default, 2 * resolution).
 *        Explicitly set values are kept. @p resolution <= 0 (a polygon map) changes nothing.
 */
Params withGridTolerances(const Params& params, double resolution);

/// The parsed ~mode (OnRequest when invalid; validate() reports it).
SolveMode solveMode(const Params& params);

/**
 * @brief Expands a leading "~" with @p home. Pure; used for ~cache_dir.
 * @return @p path unchanged unless it is "~" or starts with "~/".
 */
std::string expandUser(const std::string& path, const std::string& home);

/// The default cache folder: $ROS_HOME/fdml_localization, else $HOME/.ros/fdml_localization
/// (empty strings stand for unset variables).
std::string defaultCacheDir(const std::string& ros_home, const std::string& home);

/// A multi-line human-readable listing of every effective parameter (logged once at start).
std::string describe(const Params& params);

/**
 * @brief Reads every parameter from a tree of the node's private parameters (pure; ROS-free
 *        tests give an in-memory tree). Missing parameters keep their defaults (~map_file stays
 *        empty so validate() reports it); a value of the wrong type keeps the default and is
 *        recorded in Params::type_errors (see ParamReader). Frame ids lose a leading '/'
 *        (tf2FrameId()). ~cache_dir defaults to defaultCacheDir(@p ros_home, @p home) and a
 *        leading "~" is expanded with @p home.
 */
Params paramsFromTree(const core::ParamValue& tree, const std::string& ros_home, const std::string& home);

/// paramsFromTree() on the parameters under @p private_nh, with $ROS_HOME and $HOME.
Params loadParams(const ros::NodeHandle& private_nh);

}  // namespace fdml_localization
