#include "fdml_localization/core/localization/region_starts.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fdml_localization
{
namespace core
{
double medianFiniteRange(const std::vector<Reading>& readings)
{
  std::vector<double> finite;
  for (const Reading& r : readings)
  {
    if (std::isfinite(r.range))
    {
      finite.push_back(r.range);
    }
  }
  if (finite.empty())
  {
    return 1.0;
  }
  std::nth_element(finite.begin(), finite.begin() + finite.size() / 2, finite.end());
  return finite[finite.size() / 2];
}

double seedGate(const std::vector<Reading>& readings, const LocalizerOptions& options, const SeedScale& scale)
{
  return 3.0 * std::max(options.agreement_tolerance,
                        0.5 * scale.cell_xy + 0.5 * scale.cell_theta * medianFiniteRange(readings));
}

Pose2 freeStart(const MapRayCaster& map, const Pose2& start, double reach)
{
  const Vec2 c = start.position();
  if (map.isFree(c))
  {
    return start;
  }
  Box2 near;
  near.extend(c - Vec2(reach, reach));
  near.extend(c + Vec2(reach, reach));
  Vec2 best = c;
  double best_distance = kInf;
  const std::vector<Segment>& segments = map.grid().segments();
  map.grid().forEachSegmentInBox(near, [&](int i) {
    const Segment& s = segments[static_cast<std::size_t>(i)];
    const Vec2 d = s.b - s.a;
    if (!(d.squaredNorm() > 0.0))
    {
      return true;
    }
    const Vec2 p = closestPointOnSegment(c, s) + kOffWall * Vec2(-d.y(), d.x()).normalized();  // free side: the left
    const double distance = (p - c).norm();
    if (distance < best_distance && map.isFree(p))
    {
      best = p;
      best_distance = distance;
    }
    return true;
  });
  return Pose2(best.x(), best.y(), start.theta);
}

double agreementScore(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings, double gate)
{
  double score = 0.0;
  for (const Reading& reading : readings)
  {
    // A cast need not look beyond where the reading could still agree: the verdicts and
    // residuals of evaluatePose(), for much shorter casts where the map reaches far.
    const double r = readingResidual(map, pose, reading, gate);
    const bool agrees = std::abs(r) < gate;  // false for NaN, the sensor in a wall
    score += !agrees ? gate * gate : std::isfinite(reading.range) ? r * r : 0.0;
  }
  return score;
}

std::vector<Pose2> bestAgreeingPoses(const MapRayCaster& map, const std::vector<Pose2>& poses,
                                     const std::vector<Reading>& readings, double gate, double separation_xy,
                                     double separation_theta, std::size_t max_poses, std::size_t sampled)
{
  std::vector<std::pair<double, Pose2>> scored;
  const std::size_t n = poses.size();
  const std::size_t samples = std::min(n, sampled);
  for (std::size_t s = 0; s < samples; ++s)
  {
    const Pose2 pose = freeStart(map, poses[s * n / samples], 0.5 * separation_xy);
    scored.emplace_back(agreementScore(map, pose, readings, gate), pose);
  }
  std::stable_sort(
      scored.begin(), scored.end(),
      [](const std::pair<double, Pose2>& a, const std::pair<double, Pose2>& b) { return a.first < b.first; });
  std::vector<Pose2> best;
  for (const auto& entry : scored)
  {
    const Pose2& p = entry.second;
    const bool distinct = std::all_of(best.begin(), best.end(), [&](const Pose2& q) {
      return (p.position() - q.position()).norm() > separation_xy ||
             std::abs(angleDiff(p.theta, q.theta)) > separation_theta;
    });
    if (distinct)
    {
      best.push_back(p);
    }
    if (best.size() >= max_poses)
    {
      break;
    }
  }
  return best;
}

}  // namespace core
}  // namespace fdml_localization
