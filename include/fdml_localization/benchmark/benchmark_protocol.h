/**
 * @file benchmark_protocol.h
 * @brief The paper's benchmark protocol (method.md section 5): random trials (pose, disc
 *        obstacles, k readings) and their scoring against the ground truth.
 *
 * Used by the fdml_bench tool and its tests. Everything is deterministic given the seed.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/simulation/scene.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// How trials are drawn.
struct ProtocolOptions
{
  int readings = 10;              ///< k, in [3, 64]
  int obstacles = 10;             ///< m, number of disc obstacles (>= 0)
  double obstacle_radius = 0.1;   ///< disc radius [m] (> 0)
  bool translate = false;         ///< the robot moves between readings, not only turns
  double step_min = 0.05;         ///< translation per reading [m] (with translate)
  double step_max = 0.2;          ///< [m]
  bool moving_obstacles = false;  ///< obstacles move between readings
  double obstacle_step = 0.05;    ///< largest obstacle move per reading [m]
  double noise = 0.0;             ///< Gaussian range noise sigma [m] (>= 0)
  double max_range = kInf;        ///< sensor range [m]; beyond it a reading is +inf
  double half_angle = 0.0;        ///< every reading's cone half-angle [rad] in [0, pi/2]; 0 = rays
};

/// Every problem with the options, each naming the option and its allowed range.
std::vector<std::string> validate(const ProtocolOptions& options);

/// One drawn trial.
struct Trial
{
  Pose2 truth;                      ///< robot pose at the first reading (what is sought)
  std::vector<Pose2> sensor_poses;  ///< sensor pose in the map at each reading
  std::vector<Reading> readings;    ///< g_i relative to truth, and the measured range
  std::vector<bool> hit_static;     ///< per reading: the ray (or cone) hit the static map first
  std::vector<Obstacle> obstacles;  ///< the obstacles at the first reading
  int static_hits = 0;              ///< number of readings that hit the static map
};

/// A 64-bit seed derived from (seed, scene, m, trial), so every method and resolution sees
/// the same trials (FNV-1a over the scene name, mixed with splitmix64).
std::uint64_t trialSeed(std::uint64_t seed, const std::string& scene, int m, int trial);

/**
 * @brief Draws one trial: a random pose in free space; m discs fully inside free space (centre
 *        free, no map edge within the radius) whose centres are farther than 2 radii from every
 *        sensor position (the public prototype's rule, so a disc never covers the sensor); k readings
 *        with 2 pi / k rotation between them (plus a random collision-free step with translate;
 *        obstacles take a random step in free space between readings with moving_obstacles);
 *        each reading the nearest point of the map or a disc within its cone (Scene::castCone).
 * @throws std::invalid_argument for invalid options, std::runtime_error when the map has no
 *         room for the robot or the obstacles after many attempts.
 */
Trial generateTrial(const std::shared_ptr<const MapRayCaster>& map, const ProtocolOptions& options, std::uint64_t seed);

/// True when a disc of @p radius at @p centre lies fully in the map's free space.
bool discInFreeSpace(const MapRayCaster& map, const Vec2& centre, double radius);

/// The paper's resolution error e(n) = 2 (3 * 300 / (4 pi))^(1/3) / n (normalised units).
double paperResolutionError(int n);

/// The paper's normalised distance sqrt((dx/W)^2 + (dy/H)^2 + (dtheta/2pi)^2).
double normalisedDistance(const Pose2& a, const Pose2& b, const Box2& bounds);

/// Strict criterion defaults: 5 cm and 2 degrees.
constexpr double kStrictPosition = 0.05;
constexpr double kStrictAngle = 2.0 * kPi / 180.0;

/// The score of one localization.
struct TrialScore
{
  bool success_paper = false;   ///< nearest candidate within 2 e(n) (normalised metric)
  bool success_strict = false;  ///< nearest candidate within 5 cm and 2 degrees
  bool success_top1 = false;    ///< best-ranked candidate within 5 cm and 2 degrees
  int candidates = 0;
  double time_ms = 0.0;        ///< one localization, without the table build [ms]
  bool sparsity_held = false;  ///< at least k' readings hit the static map
  bool has_nearest = false;    ///< false when there is no candidate
  double err_pos = 0.0;        ///< nearest candidate's position error [m]
  double err_theta = 0.0;      ///< nearest candidate's absolute heading error [rad]
  double top_err_pos = 0.0;    ///< best-ranked candidate's position error [m] (has_nearest)
  double top_err_theta = 0.0;  ///< best-ranked candidate's absolute heading error [rad]
};

/**
 * @brief Scores a result. "Nearest" is the candidate nearest to the truth in the normalised
 *        metric (ties: the better-ranked); strict success also counts when the nearest in that
 *        metric misses but another candidate is within 5 cm and 2 degrees.
 * @param sparsity_k_prime k' for the sparsity check (the paper's 6 when the run is automatic)
 */
TrialScore scoreTrial(const Trial& trial, const Result& result, const Box2& bounds, int n, int sparsity_k_prime,
                      double time_ms);

}  // namespace core
}  // namespace fdml_localization
