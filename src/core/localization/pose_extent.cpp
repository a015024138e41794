// widenAlongContinua(): a candidate's covariance widened along the directions in which its
// pose can move while its readings keep agreeing (a corridor, parallel walls, a cone facing a
// flat wall), where the polish's local derivative cannot see it; settleAlongContinua(): first
// the exact place at such a continuum's end, where the polish has no gradient to reach it, or the
// stretch of it explaining more readings (continuum_gain.h).
#include "fdml_localization/core/localization/continuum_gain.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Largest move probed along a direction: 4 m in x, y; pi/2 in theta.
constexpr double kMaxShift = 4.0;
constexpr double kMaxTurn = 0.5 * kPi;

Pose2 moved(const Pose2& pose, const Eigen::Vector3d& direction, double amount)
{
  return Pose2(pose.x + amount * direction(0), pose.y + amount * direction(1), pose.theta + amount * direction(2));
}

/// True when every finite inlier of @p candidate still agrees at @p pose, each residual within
/// its value at the candidate plus @p noise [m].
bool stillAgrees(const MapRayCaster& map, const std::vector<Reading>& readings, const Candidate& candidate,
                 const std::vector<double>& residuals, const Pose2& pose, double noise)
{
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (!candidate.inlier_mask[i] || !std::isfinite(residuals[i]))
    {
      continue;
    }
    const Pose2 sensor = compose(pose, readings[i].offset);
    if (!map.isFree(sensor.position()))
    {
      return false;
    }
    const double r = predictedRange(map, sensor, readings[i], kInf) - readings[i].range;
    if (!(std::abs(r) <= std::abs(residuals[i]) + noise))
    {
      return false;
    }
  }
  return true;
}

/// Where the pose stops agreeing along a direction (one way) [m or rad]: it still agrees at
/// @c ok and no longer at @c beyond (+inf: it agrees up to the probe's limit).
struct ContinuumEnd
{
  double ok = 0.0;
  double beyond = kInf;
};

/// How far the pose can move along @p direction (one way) while it still agrees.
ContinuumEnd extent(const MapRayCaster& map, const std::vector<Reading>& readings, const Candidate& candidate,
                    const std::vector<double>& residuals, const Eigen::Vector3d& direction, double noise, double limit)
{
  ContinuumEnd end;
  double trial = 1e-3;
  while (trial <= limit &&
         stillAgrees(map, readings, candidate, residuals, moved(candidate.pose, direction, trial), noise))
  {
    end.ok = trial;
    trial *= 2.0;
  }
  if (trial > limit)
  {
    return end;
  }
  end.beyond = trial;
  for (int i = 0; i < 4; ++i)
  {
    const double mid = 0.5 * (end.ok + end.beyond);
    (stillAgrees(map, readings, candidate, residuals, moved(candidate.pose, direction, mid), noise) ? end.ok :
                                                                                                      end.beyond) = mid;
  }
  return end;
}

/// The probed directions: x, y, the heading, and the direction of each wall an inlier ray hits.
std::vector<Eigen::Vector3d> probeDirections(const MapRayCaster& map, const std::vector<Reading>& readings,
                                             const Candidate& candidate)
{
  std::vector<Eigen::Vector3d> directions{ Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(),
                                           Eigen::Vector3d::UnitZ() };
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (!candidate.inlier_mask[i] || !std::isfinite(readings[i].range))
    {
      continue;
    }
    const Pose2 sensor = compose(candidate.pose, readings[i].offset);
    const RayHit hit = map.cast(sensor.position(), sensor.heading());
    if (!hit.hit())
    {
      continue;
    }
    const Segment& seg = map.grid().segments()[static_cast<std::size_t>(hit.segment)];
    const Vec2 edge = (seg.b - seg.a).normalized();
    const Eigen::Vector3d along(edge.x(), edge.y(), 0.0);
    const bool known = std::any_of(directions.begin(), directions.end(),
                                   [&](const Eigen::Vector3d& d) { return std::abs(d.dot(along)) > 0.9998; });
    if (!known && along.allFinite())
    {
      directions.push_back(along);
    }
  }
  return directions;
}

/// A direction the pose was probed along, with both its ends.
struct Continuum
{
  Eigen::Vector3d u;
  ContinuumEnd ahead, behind;  ///< along u and along -u

  double reach() const
  {
    return std::max(ahead.ok, behind.ok);
  }
};

/// The residuals of @p candidate's readings at its pose (NaN for no-returns) [m].
std::vector<double> residualsAt(const MapRayCaster& map, const std::vector<Reading>& readings,
                                const Candidate& candidate)
{
  return evaluatePose(map, candidate.pose, readings, kInf).residuals;
}

/// The probed directions with their ends (probeDirections(), extent()), from @p candidate's
/// @p residuals (residualsAt()).
std::vector<Continuum> continua(const MapRayCaster& map, const std::vector<Reading>& readings,
                                const Candidate& candidate, const std::vector<double>& residuals, double noise)
{
  std::vector<Continuum> found;
  for (const Eigen::Vector3d& u : probeDirections(map, readings, candidate))
  {
    const double limit = u(2) != 0.0 ? kMaxTurn : kMaxShift;
    found.push_back(Continuum{ u, extent(map, readings, candidate, residuals, u, noise, limit),
                               extent(map, readings, candidate, residuals, -u, noise, limit) });
  }
  return found;
}

/// True when the pose's reach along @p c exceeds 3 standard deviations of @p covariance.
bool isContinuum(const Continuum& c, const Eigen::Matrix3d& covariance)
{
  return c.reach() * c.reach() > 9.0 * c.u.dot(covariance * c.u);
}

/// widenAlongContinua() with the probed @p found.
void widenWith(const std::vector<Continuum>& found, Candidate& candidate)
{
  for (const Continuum& c : found)
  {
    const double variance = c.u.dot(candidate.covariance * c.u);
    // A uniform spread over [-reach, reach]; only where it exceeds 3 standard deviations.
    if (isContinuum(c, candidate.covariance))
    {
      candidate.covariance += (c.reach() * c.reach() / 3.0 - variance) * c.u * c.u.transpose();
    }
  }
}

/**
 * The poses between @p candidate's and the one @p beyond along @p direction where a finite inlier
 * of @p candidate explains its reading exactly: for each one whose residual changes sign on the
 * way (from its value in @p residuals, residualsAt()), the crossing (residualSignChange()).
 */
std::vector<Pose2> residualRoots(const MapRayCaster& map, const std::vector<Reading>& readings,
                                 const Candidate& candidate, const std::vector<double>& residuals,
                                 const Eigen::Vector3d& direction, double beyond)
{
  std::vector<Pose2> roots;
  const Pose2 far = moved(candidate.pose, direction, beyond);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    if (!candidate.inlier_mask[i] || !std::isfinite(readings[i].range))
    {
      continue;
    }
    const double r0 = residuals[i];
    const double r1 = readingResidual(map, far, readings[i]);
    if (std::isfinite(r0) && std::isfinite(r1) && (r0 < 0.0) != (r1 < 0.0))
    {
      const double s = residualSignChange(map, candidate.pose, readings[i], direction, 0.0, beyond, r0, r1);
      roots.push_back(moved(candidate.pose, direction, s));
    }
  }
  return roots;
}

/// A direction is a continuum where the candidate's standard deviation along it exceeds this
/// many times the noise ([m], or [rad] per metre of it for the heading).
constexpr double kContinuumSpread = 3.0;

/// A candidate's RMS must at least halve for a pose at a continuum's end to replace it: along a
/// corridor with range noise, one reading's root moves the RMS by a fraction of the noise.
constexpr double kEndGain = 0.5;

/// Replaces @p best by a better place than @p candidate (its @p residuals) along @p c, if one ranks
/// before it (betterCandidate()): along a translation, one explaining more readings
/// (gainAlongContinuum()); for a candidate short of exact, a crossing at either end
/// (residualRoots()), polished, explaining more readings or at most halving its RMS. True when
/// one did.
bool betterAlong(const MapRayCaster& map, const std::vector<Reading>& readings, const RefinementSettings& settings,
                 const Candidate& candidate, const std::vector<double>& residuals, const Continuum& c, Candidate& best)
{
  bool replaced = false;
  if (c.u(2) == 0.0)
  {
    Candidate gained = gainAlongContinuum(map, readings, settings, candidate, c.u.head<2>(), c.behind.ok, c.ahead.ok);
    if (netConsensus(gained) > netConsensus(candidate) && betterCandidate(gained, best))
    {
      best = std::move(gained);
      replaced = true;
    }
  }
  if (candidate.rms_residual < kExactRms)
  {
    return replaced;
  }
  for (const auto& [u, end] : { std::make_pair(c.u, c.ahead), std::make_pair(Eigen::Vector3d(-c.u), c.behind) })
  {
    for (const Pose2& root : std::isfinite(end.beyond) ?
                                 residualRoots(map, readings, candidate, residuals, u, end.beyond) :
                                 std::vector<Pose2>{})
    {
      Candidate polished = polishedFrom(map, readings, settings, candidate, root);
      const bool gain =
          netConsensus(polished) > netConsensus(candidate) || polished.rms_residual < kEndGain * candidate.rms_residual;
      if (gain && betterCandidate(polished, best))
      {
        best = std::move(polished);
        replaced = true;
      }
    }
  }
  return replaced;
}

}  // namespace

Candidate polishedFrom(const MapRayCaster& map, const std::vector<Reading>& readings,
                       const RefinementSettings& settings, const Candidate& candidate, const Pose2& start)
{
  const PolishOutcome polished = polishPose(map, start, readings, candidate.inlier_mask, settings.agreement_tolerance,
                                            settings.max_iterations, settings.noise_sigma);
  Candidate c = candidateFrom(polished.pose, evaluatePose(map, polished.pose, readings, settings.agreement_tolerance));
  c.covariance = polished.covariance;
  c.support = candidate.support;
  return c;
}

void widenAlongContinua(const MapRayCaster& map, const std::vector<Reading>& readings, double noise,
                        Candidate& candidate)
{
  widenWith(continua(map, readings, candidate, residualsAt(map, readings, candidate), noise), candidate);
}

void settleAlongContinua(const MapRayCaster& map, const std::vector<Reading>& readings,
                         const RefinementSettings& settings, Candidate& candidate)
{
  const std::vector<double> residuals = residualsAt(map, readings, candidate);
  const std::vector<Continuum> found = continua(map, readings, candidate, residuals, settings.noise_sigma);
  Candidate widened = candidate;
  widenWith(found, widened);
  Candidate best = candidate;
  bool moved_on = false;
  for (const Continuum& c : found)
  {
    // Along a continuum the pose is uncertain by far more than the noise (its covariance already
    // says so where the readings leave the direction undetermined, or once widened).
    const double spread = kContinuumSpread * settings.noise_sigma;
    if (c.u.dot(widened.covariance * c.u) <= spread * spread)
    {
      continue;
    }
    moved_on = betterAlong(map, readings, settings, candidate, residuals, c, best) || moved_on;
  }
  if (!moved_on)
  {
    candidate = std::move(widened);
    return;
  }
  // Within the noise of the candidate, the continuum it lay on stays plausible (one reading 2 cm
  // off is twice a 1 cm noise): the settled pose's covariance covers it too, never a confident
  // pose 50 cm along a corridor from where noisy readings put the truth.
  const bool tie = netConsensus(best) == netConsensus(candidate) &&
                   candidate.rms_residual <= best.rms_residual + settings.noise_sigma;
  widenAlongContinua(map, readings, settings.noise_sigma, best);
  if (tie)
  {
    const Eigen::Vector3d d = poseDifference(candidate.pose, best.pose);
    best.covariance += widened.covariance + d * d.transpose();
  }
  candidate = std::move(best);
}

}  // namespace core
}  // namespace fdml_localization
