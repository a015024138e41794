// The verification suite's checks (issue 16): a trial (verification_trials.h) run on one engine,
// checked against the truth and a sampled reference, and counted. Shared by the fast gtests
// (test_verification.cpp, ...) and the long `make verify` run (verify_main.cpp).
#pragma once

#include "verification_trials.h"

#include "fdml_localization/core/localization/certificate.h"
#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/LU>
#include <Eigen/SVD>

#include <algorithm>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace verification
{
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
