#include "fdml_localization/core/localization/robust_search.h"

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

bool evaluationBetter(const PoseEvaluation& a, const PoseEvaluation& b)
{
  return rankedBefore(a.inliers, a.contradicted, a.rms, b.inliers, b.contradicted, b.rms);
}
}  // namespace

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

PoseEvaluation evaluatePose(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                            double eps)
{
  PoseEvaluation eval;
  eval.inlier_mask.assign(readings.size(), false);
  eval.residuals.assign(readings.size(), kNaN);
  double sum_sq = 0.0;
  int finite_inliers = 0;
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const Reading& reading = readings[i];
    const Pose2 sensor = compose(pose, reading.offset);
    if (!map.isFree(sensor.position()))
    {
      continue;
    }
    if (std::isfinite(reading.range))
    {
      const double h = map.range(sensor);
      const double r = h - reading.range;
      eval.residuals[i] = r;
      if (std::abs(r) < eps)
      {
        eval.inlier_mask[i] = true;
        ++eval.inliers;
        sum_sq += r * r;
        ++finite_inliers;
      }
      else if (r < 0.0)
      {
        ++eval.contradicted;
      }
    }
    else
    {
      const double h = map.range(sensor, reading.max_range + 1.0);
      if (h > reading.max_range - eps)
      {
        eval.inlier_mask[i] = true;
        ++eval.inliers;
      }
      else
      {
        ++eval.contradicted;
      }
    }
  }
  eval.rms = finite_inliers > 0 ? std::sqrt(sum_sq / finite_inliers) : 0.0;
  return eval;
}

Candidate verifiedCandidate(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                            double eps)
{
  const PoseEvaluation eval = evaluatePose(map, pose, readings, eps);
  Candidate c;
  c.pose = Pose2(pose.x, pose.y, wrapAngle(pose.theta));
  c.inlier_mask = eval.inlier_mask;
  c.inliers = eval.inliers;
  c.contradicted = eval.contradicted;
  c.rms_residual = eval.rms;
  return c;
}

Candidate refineSeed(const MapRayCaster& map, const Pose2& seed, const std::vector<Reading>& readings,
                     const std::vector<bool>& hypothesis, const RefinementSettings& settings)
{
  const double eps = settings.agreement_tolerance;
  Pose2 best_pose = seed;
  PoseEvaluation best = evaluatePose(map, seed, readings, eps);
  const std::vector<double> best_seed_residuals = best.residuals;
  Eigen::Matrix3d best_cov = Eigen::Matrix3d::Identity() * 1e6;

  // Adopts a polished pose when it explains more readings, or as many with a lower RMS.
  auto consider = [&](const PolishOutcome& polished) {
    PoseEvaluation eval = evaluatePose(map, polished.pose, readings, eps);
    if (!evaluationBetter(eval, best))
    {
      return false;
    }
    best = std::move(eval);
    best_pose = polished.pose;
    best_cov = polished.covariance;
    return true;
  };
  auto polishOn = [&](const std::vector<bool>& use, double scale) {
    return polishPose(map, best_pose, readings, use, scale, settings.max_iterations, settings.noise_sigma);
  };
  // Graduated robustness: the Cauchy scale shrinks from about the seed's error to eps, so
  // readings cut short by unknown obstacles lose their pull as the pose settles.
  auto annealFrom = [&](const Pose2& start, const std::vector<bool>& use) {
    PolishOutcome stage;
    stage.pose = start;
    for (double scale = settings.robust_scale;; scale *= 0.4)
    {
      const double s = std::max(scale, eps);
      stage = polishPose(map, stage.pose, readings, use, s, settings.max_iterations, settings.noise_sigma);
      if (s <= eps)
      {
        break;
      }
    }
    consider(stage);
  };
  auto finiteInliers = [&](int drop) {
    std::vector<bool> use(readings.size(), false);
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      use[i] = best.inlier_mask[i] && std::isfinite(readings[i].range) && static_cast<int>(i) != drop;
    }
    return use;
  };
  auto countUsed = [](const std::vector<bool>& use) {
    return static_cast<int>(std::count(use.begin(), use.end(), true));
  };
  // Re-polishes on the current inliers while that improves the consensus.
  auto polishRounds = [&]() {
    for (int round = 0; round < settings.max_rounds; ++round)
    {
      const std::vector<bool> use = finiteInliers(-1);
      if (countUsed(use) < 3)
      {
        return;
      }
      const std::vector<bool> before = best.inlier_mask;
      if (!consider(polishOn(use, 0.0)) || best.inlier_mask == before)
      {
        return;
      }
    }
  };

  // First polish: robust, on the hypothesis minus the readings whose rays pass a vertex within
  // the seed's uncertainty (most suspect first), keeping at least 4 readings.
  {
    const std::vector<double> margins = vertexMargins(map, seed, readings, settings.seed_angle_error);
    std::vector<int> used;
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      if (hypothesis[i] && std::isfinite(readings[i].range))
      {
        used.push_back(static_cast<int>(i));
      }
    }
    std::sort(used.begin(), used.end(), [&](int a, int b) { return margins[a] < margins[b]; });
    std::vector<bool> use = hypothesis;
    int remaining = static_cast<int>(used.size());
    for (int i : used)
    {
      if (remaining <= 4 || margins[i] >= settings.seed_position_error)
      {
        break;
      }
      use[i] = false;
      --remaining;
    }
    annealFrom(seed, use);
    if (use != hypothesis)
    {
      annealFrom(seed, hypothesis);
    }
    // Unknown obstacles only ever shorten readings: the readings measured shortest relative to
    // what the map predicts at the seed are the likeliest obstacle hits. While the seed does
    // not yet explain target_inliers readings, leave out the 1, 2, ... most shortened ones.
    std::vector<int> shortened;
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      const double r = best_seed_residuals[i];
      if (hypothesis[i] && std::isfinite(r) && r > settings.agreement_tolerance)
      {
        shortened.push_back(static_cast<int>(i));
      }
    }
    std::sort(shortened.begin(), shortened.end(), [&](int a, int b) {
      return best_seed_residuals[a] / std::max(readings[a].range, 1e-3) >
             best_seed_residuals[b] / std::max(readings[b].range, 1e-3);
    });
    std::vector<bool> trimmed = hypothesis;
    int kept = static_cast<int>(std::count(hypothesis.begin(), hypothesis.end(), true));
    for (std::size_t j = 0; j < shortened.size() && j < static_cast<std::size_t>(settings.max_dropped_shortened) &&
                            best.inliers < settings.target_inliers && kept > 4;
         ++j)
    {
      trimmed[shortened[j]] = false;
      --kept;
      annealFrom(seed, trimmed);
    }
  }
  // Still short of the target: the seed may sit across occlusion edges from the optimum, where
  // no descent reaches it. Search a small lattice around the seed for the pose where the most
  // readings roughly agree, and polish from there on those readings.
  if (settings.local_search_cells > 0 && best.inliers < settings.target_inliers)
  {
    const int m = settings.local_search_cells;
    const double tol = 0.5 * settings.robust_scale;
    Pose2 best_start = seed;
    PoseEvaluation best_rough = evaluatePose(map, seed, readings, tol);
    for (int a = -m; a <= m; ++a)
    {
      for (int b = -m; b <= m; ++b)
      {
        for (int c = -m; c <= m; ++c)
        {
          const Pose2 p(seed.x + a * settings.local_search_step, seed.y + b * settings.local_search_step,
                        wrapAngle(seed.theta + c * settings.local_search_angle_step));
          PoseEvaluation rough = evaluatePose(map, p, readings, tol);
          if (rough.inliers > best_rough.inliers)
          {
            best_rough = std::move(rough);
            best_start = p;
          }
        }
      }
    }
    std::vector<bool> use = best_rough.inlier_mask;
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      use[i] = use[i] && std::isfinite(readings[i].range);
    }
    if (countUsed(use) >= 3)
    {
      annealFrom(best_start, use);
    }
  }
  polishRounds();
  // The ray-cast cost is only piecewise smooth: a reading whose ray crosses an occlusion edge
  // between here and the optimum can hold the polish in a false minimum. Leave out, one at a
  // time, the readings passing nearest to a vertex and the worst one, and keep the result
  // when the consensus improves.
  for (int attempt = 0;
       attempt < settings.max_escapes && best.rms > 1e-9 && best.inliers >= settings.escape_min_inliers; ++attempt)
  {
    std::vector<int> order;
    for (std::size_t i = 0; i < readings.size(); ++i)
    {
      if (best.inlier_mask[i] && std::isfinite(readings[i].range))
      {
        order.push_back(static_cast<int>(i));
      }
    }
    if (order.size() < 4)
    {
      break;
    }
    const std::vector<double> margins = vertexMargins(map, best_pose, readings, settings.seed_angle_error);
    std::vector<int> tries;
    const int worst = *std::max_element(order.begin(), order.end(), [&](int a, int b) {
      return std::abs(best.residuals[a]) < std::abs(best.residuals[b]);
    });
    tries.push_back(worst);
    std::sort(order.begin(), order.end(), [&](int a, int b) { return margins[a] < margins[b]; });
    for (int i : order)
    {
      if (static_cast<int>(tries.size()) >= settings.escape_tries)
      {
        break;
      }
      if (i != worst)
      {
        tries.push_back(i);
      }
    }
    bool improved = false;
    for (std::size_t j = 0; j < tries.size() && !improved; ++j)
    {
      improved = consider(polishOn(finiteInliers(tries[j]), 0.0));
    }
    if (!improved)
    {
      break;
    }
    polishRounds();
  }
  Candidate c;
  c.pose = Pose2(best_pose.x, best_pose.y, wrapAngle(best_pose.theta));
  c.inlier_mask = best.inlier_mask;
  c.inliers = best.inliers;
  c.contradicted = best.contradicted;
  c.rms_residual = best.rms;
  c.covariance = best_cov;
  return c;
}

}  // namespace core
}  // namespace fdml_localization
