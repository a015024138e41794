#include "fdml_localization/benchmark/benchmark_protocol.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kMaxAttempts = 100000;
constexpr int kStepAttempts = 200;

std::uint64_t splitmix64(std::uint64_t x)
{
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// True when the segment a-b crosses or touches no map edge.
bool segmentFree(const MapRayCaster& map, const Vec2& a, const Vec2& b)
{
  Box2 box;
  box.extend(a);
  box.extend(b);
  const Segment path{ a, b };
  bool blocked = false;
  map.grid().forEachSegmentInBox(box, [&](int i) {
    blocked = segmentsIntersect(path, map.grid().segments()[static_cast<std::size_t>(i)]);
    return !blocked;
  });
  return !blocked;
}

/// A disc may sit at @p centre: inside free space, and its centre farther than 2 radii from every
/// sensor position it must avoid (the public prototype's rule: the disc keeps a gap of one radius).
bool discAllowed(const MapRayCaster& map, const Vec2& centre, double radius, const std::vector<Vec2>& avoid)
{
  for (const Vec2& p : avoid)
  {
    if ((p - centre).norm() <= 2.0 * radius)
    {
      return false;
    }
  }
  return discInFreeSpace(map, centre, radius);
}
}  // namespace

std::vector<std::string> validate(const ProtocolOptions& o)
{
  std::vector<std::string> issues;
  if (o.readings < 3 || o.readings > 64)
  {
    issues.push_back("readings (k) = " + std::to_string(o.readings) + " must be in [3, 64]");
  }
  if (o.obstacles < 0 || o.obstacles > 10000)
  {
    issues.push_back("obstacles (m) = " + std::to_string(o.obstacles) + " must be in [0, 10000]");
  }
  if (!(o.obstacle_radius > 0.0) || !std::isfinite(o.obstacle_radius))
  {
    issues.push_back("obstacle_radius must be a finite value > 0 [m]");
  }
  if (!(o.step_min >= 0.0) || !(o.step_max >= o.step_min) || !std::isfinite(o.step_max))
  {
    issues.push_back("translation step must satisfy 0 <= step_min <= step_max < inf [m]");
  }
  if (!(o.obstacle_step >= 0.0) || !std::isfinite(o.obstacle_step))
  {
    issues.push_back("obstacle_step must be a finite value >= 0 [m]");
  }
  if (!(o.noise >= 0.0) || !std::isfinite(o.noise))
  {
    issues.push_back("noise must be a finite value >= 0 [m]");
  }
  if (!(o.max_range > 0.0))
  {
    issues.push_back("max_range must be > 0 [m] (+inf for unlimited)");
  }
  if (!(o.half_angle >= 0.0 && o.half_angle <= kMaxConeHalfAngle))
  {
    issues.push_back("half_angle must be in [0, pi/2] [rad] (half the field of view; 0 = rays)");
  }
  return issues;
}

std::uint64_t trialSeed(std::uint64_t seed, const std::string& scene, int m, int trial)
{
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : scene)
  {
    h = (h ^ c) * 0x100000001b3ULL;
  }
  std::uint64_t x = splitmix64(seed);
  x = splitmix64(x ^ h);
  x = splitmix64(x ^ static_cast<std::uint64_t>(static_cast<std::uint32_t>(m)));
  return splitmix64(x ^ static_cast<std::uint64_t>(static_cast<std::uint32_t>(trial)));
}

bool discInFreeSpace(const MapRayCaster& map, const Vec2& centre, double radius)
{
  if (!map.isFree(centre))
  {
    return false;
  }
  Box2 box;
  box.extend(centre - Vec2(radius, radius));
  box.extend(centre + Vec2(radius, radius));
  const double r2 = radius * radius;
  bool touches = false;
  map.grid().forEachSegmentInBox(box, [&](int i) {
    touches = pointSegmentDistanceSquared(centre, map.grid().segments()[static_cast<std::size_t>(i)]) <= r2;
    return !touches;
  });
  return !touches;
}

namespace
{
/// The random draws of one trial, in the order the protocol has always made them.
struct TrialDraw
{
  TrialDraw(const MapRayCaster& map_in, const ProtocolOptions& options_in, std::uint64_t seed)
    : map(map_in)
    , options(options_in)
    , rng(seed)
    , ux(map_in.map().bounds().min.x(), map_in.map().bounds().max.x())
    , uy(map_in.map().bounds().min.y(), map_in.map().bounds().max.y())
    , uangle(-kPi, kPi)
  {}

  const MapRayCaster& map;
  const ProtocolOptions& options;
  std::mt19937_64 rng;
  std::uniform_real_distribution<double> ux;
  std::uniform_real_distribution<double> uy;
  std::uniform_real_distribution<double> uangle;

  /// A random direction of length in [lo, hi) [m].
  Vec2 randomStep(std::uniform_real_distribution<double>& length)
  {
    const double dir = uangle(rng);
    return length(rng) * Vec2(std::cos(dir), std::sin(dir));
  }
};

/// The robot pose in free space, then its path: 2 pi / k turn per reading, plus a
/// collision-free step with translate.
void drawRobotPath(TrialDraw& draw, Trial* trial)
{
  int attempts = 0;
  do
  {
    if (++attempts > kMaxAttempts)
    {
      throw std::runtime_error("generateTrial: found no free robot position in the map");
    }
    trial->truth = Pose2(draw.ux(draw.rng), draw.uy(draw.rng), draw.uangle(draw.rng));
  } while (!draw.map.isFree(trial->truth.position()));
  std::uniform_real_distribution<double> ustep(draw.options.step_min, draw.options.step_max);
  const double turn = kTwoPi / draw.options.readings;
  trial->sensor_poses.push_back(trial->truth);
  for (int i = 1; i < draw.options.readings; ++i)
  {
    const Pose2& prev = trial->sensor_poses.back();
    Vec2 next = prev.position();
    for (int a = 0; draw.options.translate && a < kStepAttempts; ++a)
    {
      const Vec2 cand = prev.position() + draw.randomStep(ustep);
      if (draw.map.isFree(cand) && segmentFree(draw.map, prev.position(), cand))
      {
        next = cand;
        break;
      }
    }
    trial->sensor_poses.emplace_back(next.x(), next.y(), wrapAngle(trial->truth.theta + i * turn));
  }
}

/// Discs fully in free space, never containing a sensor position.
void drawObstacles(TrialDraw& draw, const std::vector<Vec2>& positions, Trial* trial)
{
  const double r = draw.options.obstacle_radius;
  int attempts = 0;
  while (static_cast<int>(trial->obstacles.size()) < draw.options.obstacles)
  {
    if (++attempts > kMaxAttempts)
    {
      throw std::runtime_error("generateTrial: no room for " + std::to_string(draw.options.obstacles) +
                               " discs of radius " + std::to_string(r) + " m in the map");
    }
    const Vec2 c(draw.ux(draw.rng), draw.uy(draw.rng));
    if (discAllowed(draw.map, c, r, positions))
    {
      trial->obstacles.push_back(Obstacle::disc(c, r));
    }
  }
}

/// Each obstacle takes a random step in free space, away from the sensor at @p position.
void moveObstacles(TrialDraw& draw, const Vec2& position, std::vector<Obstacle>* obstacles)
{
  std::uniform_real_distribution<double> ustep(0.0, draw.options.obstacle_step);
  for (Obstacle& o : *obstacles)
  {
    for (int a = 0; a < kStepAttempts; ++a)
    {
      const Vec2 c = o.centre + draw.randomStep(ustep);
      if (discAllowed(draw.map, c, draw.options.obstacle_radius, { position }))
      {
        o.centre = c;
        break;
      }
    }
  }
}

/// The k readings: scene casts (cones of the options' half-angle) among the obstacles.
void takeReadings(TrialDraw& draw, const std::shared_ptr<const MapRayCaster>& map, Trial* trial)
{
  const ProtocolOptions& options = draw.options;
  std::normal_distribution<double> noise(0.0, options.noise > 0.0 ? options.noise : 1.0);
  const double turn = kTwoPi / options.readings;
  std::vector<Obstacle> obstacles = trial->obstacles;
  Scene scene(map);
  for (int i = 0; i < options.readings; ++i)
  {
    const Pose2& sensor = trial->sensor_poses[static_cast<std::size_t>(i)];
    if (i > 0 && options.moving_obstacles)
    {
      moveObstacles(draw, sensor.position(), &obstacles);
    }
    scene.setObstacles(obstacles);
    const SceneHit hit = scene.castCone(sensor, options.half_angle, options.max_range);
    Reading reading;
    reading.offset = options.translate ? between(trial->truth, sensor) : Pose2(0.0, 0.0, wrapAngle(i * turn));
    reading.max_range = options.max_range;
    reading.half_angle = options.half_angle;
    reading.range = hit.distance;
    if (std::isfinite(reading.range) && options.noise > 0.0)
    {
      reading.range = std::max(0.0, reading.range + noise(draw.rng));
    }
    const bool is_static = hit.kind == SceneHit::Kind::Map;
    trial->readings.push_back(reading);
    trial->hit_static.push_back(is_static);
    trial->static_hits += is_static ? 1 : 0;
  }
}
}  // namespace

Trial generateTrial(const std::shared_ptr<const MapRayCaster>& map, const ProtocolOptions& options, std::uint64_t seed)
{
  const std::vector<std::string> issues = validate(options);
  if (!issues.empty())
  {
    std::ostringstream msg;
    msg << "invalid protocol options:";
    for (const std::string& s : issues)
    {
      msg << "\n  " << s;
    }
    throw std::invalid_argument(msg.str());
  }
  if (!map || map->map().empty())
  {
    throw std::invalid_argument("generateTrial needs a non-empty map");
  }
  TrialDraw draw(*map, options, seed);
  Trial trial;
  drawRobotPath(draw, &trial);
  std::vector<Vec2> positions;
  for (const Pose2& p : trial.sensor_poses)
  {
    positions.push_back(p.position());
  }
  drawObstacles(draw, positions, &trial);
  takeReadings(draw, map, &trial);
  return trial;
}

double paperResolutionError(int n)
{
  return 2.0 * std::cbrt(3.0 * 300.0 / (4.0 * kPi)) / static_cast<double>(n);
}

double normalisedDistance(const Pose2& a, const Pose2& b, const Box2& bounds)
{
  const Vec2 size = bounds.size();
  const double dx = (a.x - b.x) / size.x();
  const double dy = (a.y - b.y) / size.y();
  const double dt = angleDiff(a.theta, b.theta) / kTwoPi;
  return std::sqrt(dx * dx + dy * dy + dt * dt);
}

TrialScore scoreTrial(const Trial& trial, const Result& result, const Box2& bounds, int n, int sparsity_k_prime,
                      double time_ms)
{
  TrialScore s;
  s.time_ms = time_ms;
  s.candidates = static_cast<int>(result.candidates.size());
  s.sparsity_held = trial.static_hits >= sparsity_k_prime;
  const auto strict = [&trial](const Pose2& p) {
    return (p.position() - trial.truth.position()).norm() <= kStrictPosition &&
           std::abs(angleDiff(p.theta, trial.truth.theta)) <= kStrictAngle;
  };
  double best = kInf;
  for (std::size_t i = 0; i < result.candidates.size(); ++i)
  {
    const Pose2& p = result.candidates[i].pose;
    const double d = normalisedDistance(p, trial.truth, bounds);
    if (d < best)
    {
      best = d;
      s.has_nearest = true;
      s.err_pos = (p.position() - trial.truth.position()).norm();
      s.err_theta = std::abs(angleDiff(p.theta, trial.truth.theta));
    }
    s.success_strict = s.success_strict || strict(p);
  }
  s.success_paper = s.has_nearest && best <= 2.0 * paperResolutionError(n);
  s.success_top1 = !result.candidates.empty() && strict(result.candidates.front().pose);
  if (!result.candidates.empty())
  {
    const Pose2& top = result.candidates.front().pose;
    s.top_err_pos = (top.position() - trial.truth.position()).norm();
    s.top_err_theta = std::abs(angleDiff(top.theta, trial.truth.theta));
  }
  return s;
}

}  // namespace core
}  // namespace fdml_localization
