#include "fdml_localization/core/localization/localizer.h"

#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/adaptive/adaptive_engine.h"
#include "fdml_localization/core/localization/no_return.h"
#include "fdml_localization/core/localization/certificate.h"

#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
std::string number(double value)
{
  std::ostringstream out;
  out << value;
  return out.str();
}

bool finitePose(const Pose2& p)
{
  return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.theta);
}
}  // namespace

const char* toString(Method method)
{
  switch (method)
  {
    case Method::Robust:
      return "robust";
    case Method::Paper:
      return "paper";
    case Method::Baseline:
      return "baseline";
  }
  return "unknown";
}

const char* toString(Engine engine)
{
  switch (engine)
  {
    case Engine::Voxel:
      return "voxel";
    case Engine::Adaptive:
      return "adaptive";
    case Engine::Auto:
      return "auto";
  }
  return "unknown";
}

Method parseMethod(const std::string& text)
{
  if (text == "robust")
  {
    return Method::Robust;
  }
  if (text == "paper")
  {
    return Method::Paper;
  }
  if (text == "baseline")
  {
    return Method::Baseline;
  }
  throw std::invalid_argument("unknown method '" + text + "' (expected robust, paper or baseline)");
}

Engine parseEngine(const std::string& text)
{
  if (text == "voxel")
  {
    return Engine::Voxel;
  }
  if (text == "adaptive")
  {
    return Engine::Adaptive;
  }
  if (text == "auto")
  {
    return Engine::Auto;
  }
  throw std::invalid_argument("unknown engine '" + text + "' (expected voxel, adaptive or auto)");
}

Engine resolveEngine(const LocalizerOptions& options)
{
  if (options.engine != Engine::Auto)
  {
    return options.engine;
  }
  return options.method == Method::Robust ? Engine::Adaptive : Engine::Voxel;
}

std::vector<std::string> validate(const LocalizerOptions& o, const std::function<std::string(const std::string&)>& name)
{
  std::vector<std::string> errors;
  const auto named = [&](const char* option) { return name ? name(option) : std::string(option); };
  const auto check = [&](bool ok, const char* option, const std::string& value, const std::string& allowed) {
    if (!ok)
    {
      errors.push_back(named(option) + " = " + value + " is out of range; allowed: " + allowed);
    }
  };
  const auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  // The voxel engine holds n x n x n_theta samples; the adaptive engine only the boxes it keeps.
  const Engine engine = resolveEngine(o);
  const int max_resolution = engine == Engine::Voxel ? kMaxVoxelResolution : kMaxAdaptiveResolution;
  const std::string range = "[16, " + std::to_string(max_resolution) + "] for engine " + toString(engine);
  check(o.resolution >= 16 && o.resolution <= max_resolution, "resolution", std::to_string(o.resolution),
        "an integer in " + range);
  check(o.theta_resolution == 0 || (o.theta_resolution >= 16 && o.theta_resolution <= max_resolution),
        "theta_resolution", std::to_string(o.theta_resolution), "0 (= resolution) or an integer in " + range);
  // k, the number of readings in a batch, is checked against k' per batch (validateReadings).
  check(o.min_inliers == 0 || (o.min_inliers >= 3 && o.min_inliers <= 255), "min_inliers",
        std::to_string(o.min_inliers), "0 (automatic) or an integer in [3, " + named("k") + "]");
  check(o.method != Method::Paper || o.min_inliers != 0, "min_inliers", std::to_string(o.min_inliers),
        "a fixed k' in [3, " + named("k") + "] with " + named("method") + " paper (automatic k' is not the paper's)");
  check(in(o.agreement_tolerance, 0.0, kMaxAgreementTolerance) && o.agreement_tolerance > 0.0, "agreement_tolerance",
        number(o.agreement_tolerance), "(0, 1e6] m (beyond the map's size: no agreement filter)");
  check(in(o.uniqueness_distance, 0.0, 100.0), "uniqueness_distance", number(o.uniqueness_distance), "[0, 100] m");
  check(in(o.uniqueness_angle, 0.0, kPi), "uniqueness_angle", number(o.uniqueness_angle), "[0, pi] rad");
  check(in(o.range_tolerance, 0.0, 10.0), "range_tolerance", number(o.range_tolerance), "[0, 10] m");
  check(o.max_candidates >= 1 && o.max_candidates <= 1000000, "max_candidates", std::to_string(o.max_candidates),
        "an integer in [1, 1000000]");
  check(o.threads >= 0 && o.threads <= 1024, "threads", std::to_string(o.threads),
        "0 (all cores) or an integer in [1, 1024]");
  check(o.max_boxes >= 1000, "max_boxes", std::to_string(o.max_boxes), "an integer >= 1000");
  check(in(o.deadline, 0.0, 3600.0), "deadline", number(o.deadline), "0 (none) or (0, 3600] s");
  check(o.no_return == NoReturnPolicy::Constraint || o.no_return == NoReturnPolicy::Weak ||
            o.no_return == NoReturnPolicy::Drop,
        "no_return", std::to_string(static_cast<int>(o.no_return)), "constraint, weak or drop");
  check(!o.search_region || o.search_region->map().area() > 0.0, "search_region", "a polygon with no area",
        "a polygon with area, or none (the whole map)");
  return errors;
}

void validateReadings(const std::vector<Reading>& readings, const LocalizerOptions& options)
{
  const int k = static_cast<int>(readings.size());
  if (k < 3)
  {
    throw InvalidInput("need at least 3 readings, got " + std::to_string(k));
  }
  if (k > 255)
  {
    throw InvalidInput("at most 255 readings per batch, got " + std::to_string(k));
  }
  for (int i = 0; i < k; ++i)
  {
    const Reading& r = readings[i];
    const std::string which = "reading " + std::to_string(i) + ": ";
    if (!finitePose(r.offset))
    {
      throw InvalidInput(which + "offset (gx, gy, gtheta) must be finite");
    }
    if (std::isnan(r.range))
    {
      throw InvalidInput(which + "range is NaN");
    }
    if (r.range < 0.0)
    {
      throw InvalidInput(which + "negative range " + number(r.range) + " m");
    }
    if (std::isnan(r.max_range) || !(r.max_range > 0.0))
    {
      throw InvalidInput(which + "max_range " + number(r.max_range) + " must be > 0 (or +inf)");
    }
    if (std::isinf(r.range) && !std::isfinite(r.max_range))
    {
      throw InvalidInput(which + "no return (range = inf) needs a finite max_range");
    }
    if (!(r.half_angle >= 0.0 && r.half_angle <= kMaxConeHalfAngle))
    {
      throw InvalidInput(which + "half_angle " + number(r.half_angle) + " rad must be in [0, pi/2]");
    }
    if (std::isfinite(r.range) && r.range > r.max_range)
    {
      throw InvalidInput(which + "range " + number(r.range) + " m exceeds max_range " + number(r.max_range) + " m");
    }
  }
  if (options.min_inliers > k)
  {
    throw InvalidInput("min_inliers k' = " + std::to_string(options.min_inliers) +
                       " exceeds the number of readings k = " + std::to_string(k));
  }
}

Box2 searchBounds(const MapRayCaster& map, const LocalizerOptions& options)
{
  Box2 bounds = map.map().bounds();
  if (options.search_region)
  {
    const Box2& region = options.search_region->map().bounds();
    bounds.min = bounds.min.cwiseMax(region.min);
    bounds.max = bounds.max.cwiseMin(region.max);
  }
  return bounds;
}

bool inSearchRegion(const LocalizerOptions& options, const Vec2& position)
{
  return !options.search_region || options.search_region->isFree(position);
}

namespace
{
/// Drops the candidates whose base lies outside the search region (a polish may move one out
/// of a box straddling the region's edge); the certificate then vouches for no region.
void keepInSearchRegion(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                        Result& result)
{
  std::vector<Candidate>& c = result.candidates;
  const std::size_t before = c.size();
  c.erase(std::remove_if(c.begin(), c.end(),
                         [&](const Candidate& x) { return !inSearchRegion(options, x.pose.position()); }),
          c.end());
  if (c.size() != before)
  {
    result.certificate.best_consensus =
        c.empty() ? 0 : consensusWithin(map, c.front().pose, readings, options.range_tolerance);
    result.certificate.complete = false;
  }
}
}  // namespace

Localizer::Localizer(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options)
  : map_(std::move(map)), options_(options)
{
  const std::vector<std::string> errors = validate(options_);
  if (!errors.empty())
  {
    std::string text = "invalid localizer options:";
    for (const std::string& e : errors)
    {
      text += "\n  " + e;
    }
    throw std::invalid_argument(text);
  }
  if (!map_ || map_->map().empty() || !(map_->map().area() > 0.0))
  {
    throw std::invalid_argument("the map has no area");
  }
  options_.engine = resolveEngine(options_);
  const Box2 searched = searchBounds(*map_, options_);
  if (options_.search_region && !(searched.size().minCoeff() > 0.0))
  {
    throw std::invalid_argument("the search region does not overlap the map's bounding box");
  }
  switch (options_.engine)
  {
    case Engine::Voxel:
      engine_ = std::make_unique<VoxelEngine>(map_, options_);
      break;
    case Engine::Adaptive:
    case Engine::Auto:
      engine_ = std::make_unique<AdaptiveEngine>(map_, options_);
      break;
  }
}

Localizer::~Localizer() = default;

void Localizer::prepare()
{
  engine_->prepare();
}

Result Localizer::localize(const std::vector<Reading>& readings)
{
  validateReadings(readings, options_);
  const bool all = options_.no_return == NoReturnPolicy::Constraint;
  std::vector<std::size_t> kept;
  const std::vector<Reading> searched = all ? readings : readingsWithReturn(readings, options_, &kept);
  Result result = engine_->localize(searched);
  const VoxelEngine* voxel = dynamic_cast<const VoxelEngine*>(engine_.get());
  if (voxel && options_.method == Method::Robust)
  {
    // The voxel engine's count field, whose maximum bounds the consensus where its preimage
    // test is conservative: the robust method's (the paper and baseline methods keep the
    // paper's own test and prove nothing; the adaptive engine certifies its own answer). Under
    // the weak and drop no-return policies the certificate speaks of the readings with a return.
    certifyVoxels(*map_, searched, options_.range_tolerance, voxel->grid(), voxel->lastCount(), result);
  }
  keepInSearchRegion(*map_, searched, options_, result);
  if (!all)
  {
    restoreNoReturns(&result, readings, kept, options_, *map_);
  }
  return result;
}

}  // namespace core
}  // namespace fdml_localization
