// widenAlongContinua(): a candidate's covariance widened along the directions in which its
// pose can move while its readings keep agreeing (a corridor, parallel walls, a cone facing a
// flat wall), where the polish's local derivative cannot see it.
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

/// How far [m or rad] the pose can move along @p direction (one way) while it still agrees.
double extent(const MapRayCaster& map, const std::vector<Reading>& readings, const Candidate& candidate,
              const std::vector<double>& residuals, const Eigen::Vector3d& direction, double noise, double limit)
{
  double ok = 0.0;
  double trial = 1e-3;
  while (trial <= limit &&
         stillAgrees(map, readings, candidate, residuals, moved(candidate.pose, direction, trial), noise))
  {
    ok = trial;
    trial *= 2.0;
  }
  if (trial > limit)
  {
    return ok;
  }
  for (int i = 0; i < 4; ++i)
  {
    const double mid = 0.5 * (ok + trial);
    (stillAgrees(map, readings, candidate, residuals, moved(candidate.pose, direction, mid), noise) ? ok : trial) = mid;
  }
  return ok;
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
}  // namespace

void widenAlongContinua(const MapRayCaster& map, const std::vector<Reading>& readings, double noise,
                        Candidate& candidate)
{
  const std::vector<double> residuals = evaluatePose(map, candidate.pose, readings, kInf).residuals;
  for (const Eigen::Vector3d& u : probeDirections(map, readings, candidate))
  {
    const double limit = u(2) != 0.0 ? kMaxTurn : kMaxShift;
    const double reach = std::max(extent(map, readings, candidate, residuals, u, noise, limit),
                                  extent(map, readings, candidate, residuals, -u, noise, limit));
    const double variance = u.dot(candidate.covariance * u);
    // A uniform spread over [-reach, reach]; only where it exceeds 3 standard deviations.
    if (reach * reach > 9.0 * variance)
    {
      candidate.covariance += (reach * reach / 3.0 - variance) * u * u.transpose();
    }
  }
}

}  // namespace core
}  // namespace fdml_localization
