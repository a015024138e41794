// Verification of a pose against the readings (exact ray and cone casts) and the vertex
// margins of its rays.
#include "fdml_localization/core/localization/robust_search.h"

#include "fdml_localization/core/geometry/cone_cast.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// Bisections of a residual's sign change (residualSignChange()): a 4 m stretch down to 0.25 um.
constexpr int kSignChangeBisections = 24;
}  // namespace

double predictedRange(const MapRayCaster& map, const Pose2& sensor, const Reading& reading, double max_range)
{
  return reading.half_angle > 0.0 ? coneRange(map, sensor, reading.half_angle, max_range) :
                                    map.range(sensor, max_range);
}

double readingResidual(const MapRayCaster& map, const Pose2& pose, const Reading& reading, double reach)
{
  const Pose2 sensor = compose(pose, reading.offset);
  if (!map.isFree(sensor.position()))
  {
    return kNaN;
  }
  if (std::isfinite(reading.range))
  {
    return predictedRange(map, sensor, reading, reading.range + reach) - reading.range;
  }
  return std::min(0.0, predictedRange(map, sensor, reading, reading.max_range + 1.0) - reading.max_range);
}

double residualSignChange(const MapRayCaster& map, const Pose2& pose, const Reading& reading,
                          const Eigen::Vector3d& direction, double a, double b, double r_a, double r_b)
{
  const bool negative_at_a = r_a < 0.0;
  for (int i = 0; i < kSignChangeBisections; ++i)
  {
    const double mid = 0.5 * (a + b);
    const Pose2 at(pose.x + mid * direction(0), pose.y + mid * direction(1), pose.theta + mid * direction(2));
    const double r = readingResidual(map, at, reading);
    if (!std::isfinite(r))
    {
      break;
    }
    ((r < 0.0) == negative_at_a ? a : b) = mid;
    ((r < 0.0) == negative_at_a ? r_a : r_b) = r;
  }
  return std::abs(r_a) <= std::abs(r_b) ? a : b;
}

std::vector<double> vertexMargins(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                                  double angle_error)
{
  std::vector<double> margins(readings.size(), kInf);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const Pose2 sensor = compose(pose, readings[i].offset);
    const Vec2 origin = sensor.position();
    if (!std::isfinite(readings[i].range) || !map.isFree(origin))
    {
      continue;
    }
    const Vec2 u = sensor.heading();
    const double reach = std::min(map.range(sensor), readings[i].range) + 0.5;
    for (const Ring& ring : map.map().rings())
    {
      for (const Vec2& v : ring)
      {
        const Vec2 rel = v - origin;
        const double t = rel.dot(u);
        if (t < 0.0 || t > reach)
        {
          continue;
        }
        const double perp = std::abs(u.x() * rel.y() - u.y() * rel.x());
        margins[i] = std::min(margins[i], perp - t * angle_error);
      }
    }
  }
  return margins;
}

std::vector<double> poseResiduals(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings)
{
  std::vector<double> residuals(readings.size());
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    residuals[i] = readingResidual(map, pose, readings[i]);
  }
  return residuals;
}

PoseEvaluation evaluateResiduals(const std::vector<double>& residuals, const std::vector<Reading>& readings, double eps)
{
  PoseEvaluation eval;
  eval.inlier_mask.assign(readings.size(), false);
  eval.residuals.assign(readings.size(), kNaN);
  double sum_sq = 0.0;
  int finite_inliers = 0;
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const double r = residuals[i];
    if (std::isnan(r))
    {
      continue;
    }
    const bool finite = std::isfinite(readings[i].range);
    eval.residuals[i] = finite ? r : kNaN;
    if (std::abs(r) < eps)
    {
      eval.inlier_mask[i] = true;
      ++eval.inliers;
      sum_sq += finite ? r * r : 0.0;
      finite_inliers += finite ? 1 : 0;
    }
    else if (r < 0.0)
    {
      ++eval.contradicted;
    }
  }
  eval.rms = finite_inliers > 0 ? std::sqrt(sum_sq / finite_inliers) : 0.0;
  return eval;
}

PoseEvaluation evaluatePose(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                            double eps)
{
  return evaluateResiduals(poseResiduals(map, pose, readings), readings, eps);
}

Candidate verifiedCandidate(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                            double eps)
{
  return candidateFrom(pose, evaluatePose(map, pose, readings, eps));
}

Candidate candidateFrom(const Pose2& pose, const PoseEvaluation& eval)
{
  Candidate c;
  c.pose = Pose2(pose.x, pose.y, wrapAngle(pose.theta));
  c.inlier_mask = eval.inlier_mask;
  c.inliers = eval.inliers;
  c.contradicted = eval.contradicted;
  c.rms_residual = eval.rms;
  return c;
}

}  // namespace core
}  // namespace fdml_localization
