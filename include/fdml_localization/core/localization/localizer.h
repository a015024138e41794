/**
 * @file localizer.h
 * @brief The robust localizer: from k range readings with known relative sensor poses g_i,
 *        find every robot pose q in the map that explains at least k' of them.
 *
 * One API, two engines: the voxel engine (the paper's voxel clouds, with counting, automatic
 * k', inlier masks and continuous polish) and the adaptive engine (branch and prune over pose
 * boxes). Construct once per map (the voxel engine's distance table is built or loaded from
 * the cache lazily on the first call, or eagerly by prepare()), then call localize() many times.
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"

#include <Eigen/Core>

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// One range reading.
struct Reading
{
  /// Sensor pose at the reading, in the base frame at the batch's first reading: g_i.
  Pose2 offset;
  /// Measured distance [m]; +inf = no return within max_range.
  double range = kInf;
  /// The sensor's maximum range [m]; +inf when unknown.
  double max_range = kInf;
  /// Half the sensor's field of view [rad] in [0, pi/2]: the reading is the nearest map point
  /// within [gtheta - a, gtheta + a] (cone_cast.h); 0 = a ray.
  double half_angle = 0.0;
};

enum class Method
{
  Robust,   ///< counting, automatic or fixed k', inlier masks, polish (ours)
  Paper,    ///< the paper exactly: fixed k', component centres, eps filter, delta uniqueness
  Baseline  ///< FDML: k' = k, no polish
};

enum class Engine
{
  Voxel,     ///< uniform n x n x n_theta grid (the paper's voxel clouds)
  Adaptive,  ///< branch and prune over boxes of poses
  Auto       ///< the faster for the job: see resolveEngine()
};

/// How readings with no return (range = +inf) are used; see no_return.h.
enum class NoReturnPolicy
{
  Constraint,  ///< agrees only where the map has no wall within max_range (a ToF sensor: no return = free)
  Weak,        ///< never an inlier nor contradicted; orders candidates tied otherwise (a lidar)
  Drop         ///< removed before the search (at least 3 readings with a return are needed)
};

const char* toString(Method method);
const char* toString(Engine engine);
const char* toString(NoReturnPolicy policy);
/// Parses "constraint" / "weak" / "drop"; throws std::invalid_argument otherwise.
NoReturnPolicy parseNoReturn(const std::string& text);
/// Parses "robust" / "paper" / "baseline"; throws std::invalid_argument otherwise.
Method parseMethod(const std::string& text);
/// Parses "voxel" / "adaptive" / "auto"; throws std::invalid_argument otherwise.
Engine parseEngine(const std::string& text);

/// Largest resolution of the voxel engine (its table holds n x n x n_theta samples).
constexpr int kMaxVoxelResolution = 1024;
/// Largest resolution of the adaptive engine (1 mm cells over a 100 m map).
constexpr int kMaxAdaptiveResolution = 100000;

/// Largest agreement tolerance [m]: beyond any map's size, i.e. no agreement filter (baseline).
constexpr double kMaxAgreementTolerance = 1e6;

/// Localizer options. validate() lists every out-of-range value.
struct LocalizerOptions
{
  Engine engine = Engine::Auto;  ///< resolved by resolveEngine() when the Localizer is built
  Method method = Method::Robust;
  int resolution = 100;               ///< cells along the map's longer side, in [16, 1024] (voxel)
                                      ///< or [16, 100000] (adaptive)
  int theta_resolution = 0;           ///< cells in theta; 0 = resolution
  int min_inliers = 0;                ///< k' in [3, k]; 0 = automatic (maximum consensus)
  double agreement_tolerance = 0.05;  ///< eps [m]: a reading agrees when |h - d| < eps
  double uniqueness_distance = 0.1;   ///< delta: candidates closer than this [m] ...
  double uniqueness_angle = 0.1;      ///< ... and this [rad] are duplicates
  double range_tolerance = 0.02;      ///< tau: sensor noise band [m] used by the preimages
  int max_candidates = 10;            ///< at most this many candidates are returned (>= 1)
  int threads = 0;                    ///< OpenMP threads; 0 = all cores
  std::string cache_dir;              ///< distance-table cache folder; empty = no disk cache
  // Adaptive engine budget.
  long max_boxes = 20000000;  ///< stop subdividing after this many boxes (>= 1000)
  /// Wall-time budget per call [s]; 0 = none. The adaptive engine's box search stops at it; the
  /// robust search (both engines) refines no more seeds, stops lowering k' and enumerates no
  /// more of a region's poses past it (the budget counted again from its start), ranking what it
  /// found.
  double deadline = 0.0;
  /// Readings with no return: constraints (the default), weak evidence, or dropped.
  NoReturnPolicy no_return = NoReturnPolicy::Constraint;
  /// Where the robot's base may be (its free space; null = anywhere in the map). The search
  /// covers this region's bounding box cut to the map's (so resolution counts cells along that
  /// box's longer side) and only poses whose base may lie in the region; candidates outside it
  /// are dropped. Rays still meet every wall of the map, inside the region or not.
  std::shared_ptr<const MapRayCaster> search_region;
};

/**
 * @brief The engine a Localizer runs: options.engine, or for Engine::Auto the adaptive engine
 *        with the robust method and the voxel engine with the paper's and the baseline's (their
 *        semantics are those of the paper's voxel clouds). With the robust method the adaptive
 *        engine was the faster at every map size measured, from a 2 m room to a 60 x 40 m
 *        building (2 to 30 times per call at resolution 100, and it builds no table:
 *        docs/BENCHMARKS.md, "Choosing the engine").
 */
Engine resolveEngine(const LocalizerOptions& options);

/**
 * @brief The box of base positions the search covers [m]: the map's bounding box, cut to the
 *        search region's when one is set (empty when they do not overlap).
 */
Box2 searchBounds(const MapRayCaster& map, const LocalizerOptions& options);

/// True when @p position [m] lies in the search region (always without one).
bool inSearchRegion(const LocalizerOptions& options, const Vec2& position);

/**
 * @brief The one validation of the options: every problem, each as "NAME = VALUE is out of
 *        range; allowed: RANGE". ROS parameters and tool flags map onto the options and report
 *        these errors under their own names.
 * @param name maps an option's name (e.g. "resolution") to the caller's name for it (e.g.
 *        "~resolution" or "--resolution"); empty = the option's own name
 */
std::vector<std::string> validate(const LocalizerOptions& options,
                                  const std::function<std::string(const std::string&)>& name = {});

/// Thrown by localize() for unusable input (NaN or negative ranges, too few readings, ...).
class InvalidInput : public std::invalid_argument
{
public:
  using std::invalid_argument::invalid_argument;
};

/**
 * @brief Checks a batch against the options: at least 3 and at most 255 readings, finite
 *        offsets, ranges >= 0 and not NaN, a finite max_range > 0 for every no-return reading,
 *        no finite range beyond its max_range, and k' <= k.
 * @throws InvalidInput naming the first problem (and the reading's index)
 */
void validateReadings(const std::vector<Reading>& readings, const LocalizerOptions& options);

/// One candidate pose.
struct Candidate
{
  Pose2 pose;                     ///< robot base pose in the map frame at the first reading
  std::vector<bool> inlier_mask;  ///< per reading: agrees with the static map
  int inliers = 0;
  /// Readings measured longer than the map allows at this pose (beyond eps), or with no return
  /// where the map has a wall in range: no unknown obstacle explains them (they only shorten
  /// readings), so each counts against the pose (ranking: inliers - contradicted first).
  int contradicted = 0;
  double rms_residual = 0.0;                             ///< over the inliers [m]
  double support = 0.0;                                  ///< voxels (or boxes) of the component it came from
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of (x, y, theta) from the polish
};

/// Wall time of each stage [s].
struct StageTimes
{
  double table = 0.0;  ///< distance table build or cache load (first call only)
  double preimages = 0.0;
  double count = 0.0;
  double components = 0.0;
  double verification = 0.0;
  double polish = 0.0;
  double total = 0.0;
};

/**
 * @brief What the search proved about its answer (certificate.h). Every figure counts the
 *        readings a pose explains within the range tolerance tau (LocalizerOptions::
 *        range_tolerance): |h - d| <= tau, the sensor in free space, a no-return reading when
 *        nothing in range is nearer than max_range - tau. Poses are those of the searched space
 *        (searchBounds() x [-pi, pi), the robot's base in free space and in the search region).
 */
struct Certificate
{
  /// Proved upper bound: no pose explains more readings than this. It comes from the search's
  /// conservative tests (the adaptive engine's largest leaf or set-aside box count, the voxel
  /// count field's maximum). -1 = no bound (the engine proves none).
  int max_consensus_bound = -1;
  /// Readings the best candidate explains (0 without candidates). Equal to the bound: the bound
  /// is attained, the maximum consensus is proved.
  int best_consensus = 0;
  /// Connected regions of boxes (voxels) whose count reaches the bound: every pose that may
  /// explain max_consensus_bound readings lies in one of them.
  int regions_at_bound = 0;
  /// ... of which hold a returned candidate.
  int regions_covered = 0;
  /// ... of which hold none but were proved empty: a finer subdivision of their boxes with the
  /// same conservative test left no box that may reach the bound.
  int regions_excluded = 0;
  /// best_consensus == max_consensus_bound, every region at the bound covered or excluded, and
  /// no box that may reach the bound left unresolved by a search budget: the best candidate
  /// explains the most readings any pose can, and every pose that can is in the region of a
  /// returned candidate.
  bool complete = false;
};

/// The outcome of one localize() call.
struct Result
{
  std::vector<Candidate> candidates;  ///< best first: see betterCandidate() (ranking.h)
  int readings_used = 0;
  int min_inliers_used = 0;  ///< k' actually used
  bool truncated = false;    ///< a search budget was reached (adaptive engine)
  StageTimes times;
  std::vector<long> boxes_per_level;  ///< adaptive engine: boxes kept at each level
  Engine engine = Engine::Voxel;
  Method method = Method::Robust;
  Certificate certificate;  ///< what the search proved (see Certificate)
};

/// The engine interface behind Localizer.
class LocalizerEngine
{
public:
  virtual ~LocalizerEngine() = default;
  virtual void prepare() = 0;
  virtual Result localize(const std::vector<Reading>& readings) = 0;
};

/**
 * @brief The public entry point. Not thread-safe: use one Localizer per thread
 *        (each call is internally parallel with OpenMP).
 */
class Localizer
{
public:
  /// @throws std::invalid_argument listing every problem of @p options, or for an empty map.
  Localizer(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options);
  ~Localizer();

  /// Builds or loads precomputed tables now instead of on the first localize().
  void prepare();

  /// @throws InvalidInput for unusable readings (the message names the problem).
  Result localize(const std::vector<Reading>& readings);

  const LocalizerOptions& options() const
  {
    return options_;
  }
  const MapRayCaster& map() const
  {
    return *map_;
  }
  /// The engine behind this localizer (for diagnostics and tests).
  LocalizerEngine& engine()
  {
    return *engine_;
  }

private:
  std::shared_ptr<const MapRayCaster> map_;
  LocalizerOptions options_;
  std::unique_ptr<LocalizerEngine> engine_;
};

}  // namespace core
}  // namespace fdml_localization
