// A candidate moved along its continuum to where it explains more readings (continuum_gain.h).
#include "fdml_localization/core/localization/continuum_gain.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fdml_localization
{
namespace core
{
namespace
{
/// @p pose moved by @p s [m] along the unit translation @p u, its heading kept.
Pose2 shifted(const Pose2& pose, const Eigen::Vector2d& u, double s)
{
  return Pose2(pose.x + s * u.x(), pose.y + s * u.y(), pose.theta);
}

/// Appends the offsets [m] along @p u, within (@p lo, @p hi), where @p reading's ray from @p pose
/// passes a map vertex within its max range: there what the ray hits can jump (it passes a wall's
/// end); between them its range changes continuously.
void vertexCrossings(const MapRayCaster& map, const Pose2& pose, const Reading& reading, const Eigen::Vector2d& u,
                     double lo, double hi, std::vector<double>& offsets)
{
  const Pose2 sensor = compose(pose, reading.offset);
  const Vec2 w(std::cos(sensor.theta), std::sin(sensor.theta));
  const double across = u.x() * w.y() - u.y() * w.x();
  if (std::abs(across) < 1e-9)
  {
    return;  // the ray slides along itself: it passes no vertex
  }
  for (const Ring& ring : map.map().rings())
  {
    for (const Vec2& v : ring)
    {
      // The vertex lies on the ray moved by s where (v - sensor - s u) x w = 0.
      const Vec2 d = v - sensor.position();
      const double s = (d.x() * w.y() - d.y() * w.x()) / across;
      const double along = (d - s * u).dot(w);
      if (s > lo && s < hi && along > 0.0 && along <= reading.max_range)
      {
        offsets.push_back(s);
      }
    }
  }
}

/// Appends the offset between @p a and @p b along @p u where @p reading's residual from @p pose
/// changes sign (residualSignChange()) when its residuals there, @p r_a and @p r_b, differ in sign.
void residualCrossing(const MapRayCaster& map, const Pose2& pose, const Reading& reading, const Eigen::Vector2d& u,
                      double a, double b, double r_a, double r_b, std::vector<double>& offsets)
{
  if (std::isfinite(r_a) && std::isfinite(r_b) && (r_a < 0.0) != (r_b < 0.0))
  {
    offsets.push_back(residualSignChange(map, pose, reading, Eigen::Vector3d(u.x(), u.y(), 0.0), a, b, r_a, r_b));
  }
}

/// True for a reading the offsets follow: outside @p candidate's inliers, a ray.
bool followed(const Candidate& candidate, const std::vector<Reading>& readings, std::size_t i)
{
  return !candidate.inlier_mask[i] && readings[i].half_angle == 0.0;
}

/// The offsets gainAlongContinuum() tries, each with the length of its stretch [m] (0 for a sign
/// change).
std::vector<std::pair<double, double>> offsetsToTry(const MapRayCaster& map, const std::vector<Reading>& readings,
                                                    const Candidate& candidate, const Eigen::Vector2d& u, double behind,
                                                    double ahead)
{
  std::vector<double> cuts{ -behind, ahead };
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (followed(candidate, readings, i))
    {
      vertexCrossings(map, candidate.pose, readings[i], u, -behind, ahead, cuts);
    }
  }
  std::sort(cuts.begin(), cuts.end());
  // The residual at every cut of each finite reading followed, cast once for both its stretches.
  std::vector<std::vector<double>> at_cuts(readings.size());
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (followed(candidate, readings, i) && std::isfinite(readings[i].range))
    {
      for (const double cut : cuts)
      {
        at_cuts[i].push_back(readingResidual(map, shifted(candidate.pose, u, cut), readings[i]));
      }
    }
  }
  std::vector<std::pair<double, double>> tries;
  for (std::size_t j = 0; j + 1 < cuts.size(); ++j)
  {
    tries.emplace_back(0.5 * (cuts[j] + cuts[j + 1]), cuts[j + 1] - cuts[j]);
    std::vector<double> roots;
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      if (!at_cuts[i].empty())
      {
        residualCrossing(map, candidate.pose, readings[i], u, cuts[j], cuts[j + 1], at_cuts[i][j], at_cuts[i][j + 1],
                         roots);
      }
    }
    for (const double root : roots)
    {
      tries.emplace_back(root, 0.0);
    }
  }
  return tries;
}

}  // namespace

Candidate gainAlongContinuum(const MapRayCaster& map, const std::vector<Reading>& readings,
                             const RefinementSettings& settings, const Candidate& candidate,
                             const Eigen::Vector2d& direction, double behind, double ahead)
{
  Candidate best = candidate;
  double best_length = -1.0;
  for (const auto& [offset, length] : offsetsToTry(map, readings, candidate, direction, behind, ahead))
  {
    const Pose2 pose = shifted(candidate.pose, direction, offset);
    Candidate at = candidateFrom(pose, evaluatePose(map, pose, readings, settings.agreement_tolerance));
    const int gain = netConsensus(at) - netConsensus(best);
    if (netConsensus(at) > netConsensus(candidate) && (gain > 0 || (gain == 0 && length > best_length)))
    {
      best = std::move(at);
      best_length = length;
    }
  }
  if (best_length < 0.0)
  {
    return candidate;
  }
  best.support = candidate.support;
  Candidate polished = polishedFrom(map, readings, settings, best, best.pose);
  if (betterCandidate(polished, best))
  {
    return polished;
  }
  ensureCovariance(map, readings, settings.noise_sigma, best);
  return best;
}

}  // namespace core
}  // namespace fdml_localization
