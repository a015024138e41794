// The verification suite (issue 16): random trials over reading geometries on small maps, both
// engines, noise-free and noisy, checked against the truth and a sampled reference. Shared by
// the fast gtest (test_verification.cpp) and the long `make verify` run (verify_main.cpp).
#pragma once

#include "fdml_localization/core/localization/certificate.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/robust_search.h"

#include "localizer_test_utils.h"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <array>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace verification
{
constexpr double kDeg = kPi / 180.0;

enum Geometry
{
  kTurning,   ///< one sensor at the centre turning in place, 2 pi / k apart
  kDriving,   ///< four sensors (front, left, back, right, 0.15 m) driving 1 cm per reading
  kRandom,    ///< one sensor at the centre, random directions
  kGrazing,   ///< turning in place, the first ray aimed within 0.05 deg of a map vertex
  kNoReturn,  ///< turning in place with a max range of 1 to 2.5 m (some readings return nothing)
  kGeometries
};

inline const char* geometryName(int g)
{
  static const char* names[] = { "turning", "driving", "random", "grazing", "no-return" };
  return names[g];
}

/// One trial's inputs.
struct Trial
{
  int map = 0;
  int geometry = kTurning;
  bool noisy = false;
  Pose2 truth;
  std::vector<Reading> readings;
};

/// The small maps of the suite.
inline std::vector<std::shared_ptr<const MapRayCaster>> smallMaps()
{
  return { test::loadMap("maps/l_room.poly"), test::lRoomMap(), test::loadMap("maps/square_room.poly") };
}

/// The options of a verification trial: @p engine at @p resolution, one thread.
inline LocalizerOptions trialOptions(Engine engine, int resolution = 64)
{
  LocalizerOptions options;
  options.engine = engine;
  options.resolution = resolution;
  options.threads = 1;
  return options;
}

/// One localizer with trialOptions() per map of @p maps.
inline std::vector<std::unique_ptr<Localizer>>
localizersFor(const std::vector<std::shared_ptr<const MapRayCaster>>& maps, Engine engine, int resolution = 64)
{
  std::vector<std::unique_ptr<Localizer>> localizers;
  for (const auto& map : maps)
  {
    localizers.push_back(std::make_unique<Localizer>(map, trialOptions(engine, resolution)));
  }
  return localizers;
}

/// localizersFor() the maps of smallMaps().
inline std::vector<std::unique_ptr<Localizer>> smallMapLocalizers(Engine engine)
{
  return localizersFor(smallMaps(), engine);
}

inline std::vector<Pose2> trialOffsets(int geometry, int k, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  std::vector<Pose2> offsets;
  const Pose2 mounts[4] = { Pose2(0.15, 0.0, 0.0), Pose2(0.0, 0.15, 0.5 * kPi), Pose2(-0.15, 0.0, kPi),
                            Pose2(0.0, -0.15, -0.5 * kPi) };
  for (int i = 0; i < k; ++i)
  {
    if (geometry == kDriving)
    {
      offsets.push_back(compose(Pose2(0.01 * i, 0.0, 0.0), mounts[i % 4]));
    }
    else
    {
      offsets.emplace_back(0.0, 0.0, geometry == kRandom ? angle(rng) : wrapAngle(kTwoPi * i / k));
    }
  }
  return offsets;
}

/// A truth whose every sensor position is in free space; for kGrazing its heading aims the
/// first ray within 0.05 deg of a visible map vertex.
inline Pose2 trialTruth(const MapRayCaster& map, int geometry, const std::vector<Pose2>& offsets, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (;;)
  {
    Pose2 truth = test::randomFreePose(map, rng, 0.1);
    if (geometry == kGrazing)
    {
      std::vector<Vec2> vertices;
      for (const Ring& ring : map.map().rings())
      {
        vertices.insert(vertices.end(), ring.begin(), ring.end());
      }
      const Vec2 v = vertices[static_cast<std::size_t>(unit(rng) * vertices.size()) % vertices.size()];
      const Vec2 d = v - truth.position();
      truth.theta = wrapAngle(std::atan2(d.y(), d.x()) + (unit(rng) - 0.5) * 0.1 * kDeg);
      if (std::abs(map.range(truth) - d.norm()) > 0.05 && map.range(truth) < d.norm())
      {
        continue;  // the vertex is hidden
      }
    }
    bool clear = true;
    for (const Pose2& g : offsets)
    {
      const Vec2 p = compose(truth, g).position();
      clear = clear && map.isFree(p) && test::clearance2(map, p) > 0.01 * 0.01;
    }
    if (clear)
    {
      return truth;
    }
  }
}

/// Readings per trial, drawn uniformly from [kMinReadings, kMaxReadings] unless told otherwise.
constexpr int kMinReadings = 4;
constexpr int kMaxReadings = 30;

/// A random trial on one of @p maps: geometry, noise, k in [@p k_min, @p k_max] and the truth.
inline Trial makeTrial(const std::vector<std::shared_ptr<const MapRayCaster>>& maps, std::mt19937_64& rng,
                       int k_min = kMinReadings, int k_max = kMaxReadings)
{
  std::uniform_int_distribution<int> pick_map(0, static_cast<int>(maps.size()) - 1), pick_geometry(0, kGeometries - 1),
      pick_k(k_min, k_max);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.005);
  Trial trial;
  trial.map = pick_map(rng);
  trial.geometry = pick_geometry(rng);
  trial.noisy = unit(rng) < 0.5;
  const MapRayCaster& map = *maps[static_cast<std::size_t>(trial.map)];
  const std::vector<Pose2> offsets = trialOffsets(trial.geometry, pick_k(rng), rng);
  trial.truth = trialTruth(map, trial.geometry, offsets, rng);
  trial.readings = test::exactReadings(map, trial.truth, offsets);
  const double max_range = trial.geometry == kNoReturn ? 1.0 + 1.5 * unit(rng) : kInf;
  for (Reading& r : trial.readings)
  {
    r.range = trial.noisy ? std::max(0.0, r.range + noise(rng)) : r.range;
    r.max_range = max_range;
    r.range = r.range > max_range ? kInf : r.range;
  }
  return trial;
}

/**
 * The direction (x, y, theta) along which the finite readings do not determine the pose at
 * @p truth (the right singular vector of the ranges' Jacobian with a singular value below 1e-3
 * of the largest; any when fewer than 3 readings are finite), or zero when they determine it.
 */
inline Eigen::Vector3d undeterminedDirection(const MapRayCaster& map, const Pose2& truth,
                                             const std::vector<Reading>& readings)
{
  const double step = 1e-5;
  std::vector<const Reading*> finite;
  for (const Reading& r : readings)
  {
    if (std::isfinite(r.range))
    {
      finite.push_back(&r);
    }
  }
  if (finite.size() < 3)
  {
    return Eigen::Vector3d::UnitZ();
  }
  Eigen::MatrixXd jacobian(finite.size(), 3);
  for (int axis = 0; axis < 3; ++axis)
  {
    Pose2 plus = truth;
    Pose2 minus = truth;
    (axis == 0 ? plus.x : axis == 1 ? plus.y : plus.theta) += step;
    (axis == 0 ? minus.x : axis == 1 ? minus.y : minus.theta) -= step;
    for (std::size_t i = 0; i < finite.size(); ++i)
    {
      jacobian(static_cast<Eigen::Index>(i), axis) =
          (predictedRange(map, compose(plus, finite[i]->offset), *finite[i], kInf) -
           predictedRange(map, compose(minus, finite[i]->offset), *finite[i], kInf)) /
          (2.0 * step);
    }
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(jacobian, Eigen::ComputeThinV);
  const Eigen::Vector3d s = svd.singularValues();
  return s(2) < 1e-3 * s(0) ? Eigen::Vector3d(svd.matrixV().col(2)) : Eigen::Vector3d::Zero();
}

/// What the trials found, per engine.
struct Figures
{
  int trials = 0;
  int noise_free = 0;
  int missed = 0;        ///< noise-free: the truth not among the candidates (nor tied out)
  int undetermined = 0;  ///< noise-free trials whose readings do not determine the pose
  int inaccurate = 0;    ///< noise-free: the best candidate is the truth's but beyond 1 cm, 0.5 deg
  int contradicted = 0;  ///< certificates a reference pose contradicts (it exceeds the bound)
  /// Complete certificates with a reference pose reaching the bound 0.3 m or 0.2 rad from every
  /// candidate: not a contradiction when the pose lies in a candidate's (large) region, which
  /// the reference cannot see; counted, not failed.
  int far_optima = 0;
  int complete = 0;
  int top1 = 0;  ///< the best candidate within 5 cm and 2 deg
  double seconds = 0.0;
  std::vector<std::string> failures;
};

/// True when @p c is the truth's candidate: within 5 cm and 2 deg, or an exact pose on a
/// continuum the truth belongs to whose covariance covers the truth (3 sigma).
inline bool isTruths(const Candidate& c, const Pose2& truth)
{
  if (test::positionError(c.pose, truth) < 0.05 && test::angleError(c.pose, truth) < 2.0 * kDeg)
  {
    return true;
  }
  const Eigen::Vector3d d(truth.x - c.pose.x, truth.y - c.pose.y, angleDiff(truth.theta, c.pose.theta));
  return c.rms_residual < 1e-6 && d.dot(c.covariance.inverse() * d) <= 9.0;
}

/**
 * The reference: the truth and @p samples random poses (the best few refined by the polish);
 * any of them explaining more readings within tau than the bound contradicts the certificate, and
 * so does a complete certificate when one reaching the bound lies far from every candidate.
 */
inline const char* contradicts(const MapRayCaster& map, const Trial& trial, const Result& result, double tau,
                               int samples, std::mt19937_64& rng)
{
  const Certificate& cert = result.certificate;
  std::vector<std::pair<int, Pose2>> poses{ { consensusWithin(map, trial.truth, trial.readings, tau), trial.truth } };
  for (int s = 0; s < samples; ++s)
  {
    const Pose2 p = test::randomFreePose(map, rng, 0.0);
    poses.emplace_back(evaluatePose(map, p, trial.readings, 0.1).inliers, p);
  }
  std::partial_sort(poses.begin() + 1, poses.begin() + std::min<std::size_t>(6, poses.size()), poses.end(),
                    [](const std::pair<int, Pose2>& a, const std::pair<int, Pose2>& b) { return a.first > b.first; });
  for (std::size_t j = 0; j < poses.size() && j < 6; ++j)
  {
    Pose2 p = poses[j].second;
    if (j > 0)
    {
      std::vector<bool> use(trial.readings.size());
      for (std::size_t i = 0; i < use.size(); ++i)
      {
        use[i] = std::isfinite(trial.readings[i].range);
      }
      p = polishPose(map, p, trial.readings, use, 0.05, 30, 0.01).pose;
    }
    const int consensus = consensusWithin(map, p, trial.readings, tau);
    if (consensus > cert.max_consensus_bound)
    {
      return j == 0 ? "the truth exceeds the bound" : "a reference pose exceeds the bound";
    }
    const bool near_candidate =
        std::any_of(result.candidates.begin(), result.candidates.end(), [&](const Candidate& c) {
          return (test::positionError(c.pose, p) < 0.3 && test::angleError(c.pose, p) < 0.2) || isTruths(c, p);
        });
    if (cert.complete && consensus == cert.max_consensus_bound && !near_candidate)
    {
      return j == 0 ? "complete, but the truth reaches the bound far from every candidate" :
                      "complete, but a reference pose reaches the bound far from every candidate";
    }
  }
  return nullptr;
}

/// The checks of a noise-free trial: the truth among the candidates (or, where the readings
/// leave the pose undetermined, the maximum consensus reached) and the best candidate accurate.
inline void checkNoiseFree(const Localizer& localizer, const Trial& trial, const Result& result,
                           const std::string& label, Figures& figures)
{
  const MapRayCaster& map = localizer.map();
  const auto truths = std::find_if(result.candidates.begin(), result.candidates.end(),
                                   [&](const Candidate& c) { return isTruths(c, trial.truth); });
  const Candidate at_truth =
      verifiedCandidate(map, trial.truth, trial.readings, localizer.options().agreement_tolerance);
  if (!undeterminedDirection(map, trial.truth, trial.readings).isZero())
  {
    // A continuum of poses explains the readings: the best candidate must explain as many.
    ++figures.undetermined;
    if (result.candidates.empty() || netConsensus(at_truth) > netConsensus(result.candidates.front()))
    {
      ++figures.missed;
      figures.failures.push_back(std::string("maximum consensus missed (undetermined pose): ") + label);
    }
    return;
  }
  if (truths == result.candidates.end())
  {
    // Not a miss when the list is full of candidates at least as good as the truth (ties; exact
    // places tie whatever their RMS below 1e-6, the rounding of their polish).
    const auto tiesWithTruth = [&](const Candidate& last) {
      const bool exact_tie = netConsensus(at_truth) == netConsensus(last) &&
                             at_truth.contradicted == last.contradicted && last.rms_residual < 1e-6;
      return exact_tie || !betterCandidate(at_truth, last);
    };
    const bool tied_out = static_cast<int>(result.candidates.size()) >= localizer.options().max_candidates &&
                          tiesWithTruth(result.candidates.back());
    if (!tied_out)
    {
      ++figures.missed;
      figures.failures.push_back(std::string("truth missed: ") + label);
    }
    return;
  }
  if (truths == result.candidates.begin() &&
      (test::positionError(truths->pose, trial.truth) > 0.01 ||
       test::angleError(truths->pose, trial.truth) > 0.5 * kDeg) &&
      truths->rms_residual > 1e-6)
  {
    ++figures.inaccurate;
    figures.failures.push_back(std::string("best candidate inaccurate: ") + label);
  }
}

/// What reproduces a trial: map, geometry, k, truth, and the max range (no-return) or the
/// headings (random directions) that the truth alone does not give.
inline std::string trialLabel(const Trial& trial, int k)
{
  // 17 significant digits: every double prints as itself, so the replay is bit-exact.
  char text[200];
  std::snprintf(text, sizeof(text), "%s map %d k %d %s truth (%.17g, %.17g, %.17g)", geometryName(trial.geometry),
                trial.map, k, trial.noisy ? "noisy" : "exact", trial.truth.x, trial.truth.y, trial.truth.theta);
  std::string label = text;
  if (trial.geometry == kNoReturn && !trial.readings.empty())
  {
    std::snprintf(text, sizeof(text), " max range %.17g", trial.readings.front().max_range);
    label += text;
  }
  if (trial.geometry == kRandom)
  {
    label += " headings";
    for (const Reading& r : trial.readings)
    {
      std::snprintf(text, sizeof(text), " %.17g", r.offset.theta);
      label += text;
    }
  }
  return label;
}

/// Runs one trial on @p localizer and adds it to @p figures.
inline void runTrial(Localizer& localizer, const Trial& trial, int reference_samples, std::mt19937_64& rng,
                     Figures& figures)
{
  const MapRayCaster& map = localizer.map();
  const Result result = localizer.localize(trial.readings);
  ++figures.trials;
  figures.seconds += result.times.total;
  figures.complete += result.certificate.complete ? 1 : 0;
  const int k = static_cast<int>(trial.readings.size());
  const std::string label = trialLabel(trial, k);
  if (!result.candidates.empty() && isTruths(result.candidates[0], trial.truth))
  {
    ++figures.top1;
  }
  if (const char* why = contradicts(map, trial, result, localizer.options().range_tolerance, reference_samples, rng))
  {
    const bool exceeded = std::string(why).find("exceeds") != std::string::npos;
    (exceeded ? figures.contradicted : figures.far_optima) += 1;
    if (exceeded)
    {
      figures.failures.push_back(std::string("certificate contradicted (") + why + "): " + label);
    }
  }
  if (!trial.noisy)
  {
    ++figures.noise_free;
    checkNoiseFree(localizer, trial, result, label, figures);
  }
}

}  // namespace verification
}  // namespace core
}  // namespace fdml_localization
