#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <utility>

namespace fdml_localization
{
namespace core
{
bool rankedBefore(int inliers_a, int contradicted_a, double rms_a, int inliers_b, int contradicted_b, double rms_b)
{
  const int net_a = inliers_a - contradicted_a;
  const int net_b = inliers_b - contradicted_b;
  if (net_a != net_b)
  {
    return net_a > net_b;
  }
  return contradicted_a != contradicted_b ? contradicted_a < contradicted_b : rms_a < rms_b;
}

bool betterCandidate(const Candidate& a, const Candidate& b)
{
  return rankedBefore(a.inliers, a.contradicted, a.rms_residual, b.inliers, b.contradicted, b.rms_residual);
}

bool exactTie(const Candidate& a, const Candidate& b)
{
  return netConsensus(a) == netConsensus(b) && a.contradicted == b.contradicted && a.rms_residual < kExactRms &&
         b.rms_residual < kExactRms;
}

bool withinMargins(const Pose2& a, const Pose2& b, double distance, double angle)
{
  return std::hypot(a.x - b.x, a.y - b.y) < distance && std::abs(angleDiff(a.theta, b.theta)) < angle;
}

std::vector<Candidate> rankAndDeduplicate(std::vector<Candidate> candidates, double distance, double angle,
                                          int max_candidates)
{
  std::stable_sort(candidates.begin(), candidates.end(), betterCandidate);
  std::vector<Candidate> kept;
  for (Candidate& c : candidates)
  {
    if (static_cast<int>(kept.size()) >= max_candidates)
    {
      break;
    }
    const bool duplicate = std::any_of(
        kept.begin(), kept.end(), [&](const Candidate& k) { return withinMargins(c.pose, k.pose, distance, angle); });
    if (!duplicate)
    {
      kept.push_back(std::move(c));
    }
  }
  return kept;
}

void absorbTiedDuplicates(const std::vector<Candidate>& all, double distance, double angle, double noise,
                          std::vector<Candidate>& kept)
{
  for (const Candidate& c : all)
  {
    for (Candidate& k : kept)
    {
      if (!withinMargins(c.pose, k.pose, distance, angle))
      {
        continue;
      }
      const Eigen::Vector3d d = poseDifference(c.pose, k.pose);
      const double mahalanobis2 = d.dot(k.covariance.ldlt().solve(d));
      if (netConsensus(c) == netConsensus(k) && c.rms_residual <= k.rms_residual + noise && !(mahalanobis2 <= 9.0))
      {
        k.covariance += d * d.transpose() / 8.0;
      }
      break;  // c is a duplicate of the first kept candidate near it (rankAndDeduplicate())
    }
  }
}

std::vector<Candidate> rankAndAbsorbDuplicates(const std::vector<Candidate>& candidates, double distance, double angle,
                                               double noise, int max_candidates)
{
  std::vector<Candidate> kept = rankAndDeduplicate(candidates, distance, angle, max_candidates);
  absorbTiedDuplicates(candidates, distance, angle, noise, kept);
  return kept;
}

bool isUnambiguous(const Result& result)
{
  const std::vector<Candidate>& c = result.candidates;
  return c.size() == 1 || (c.size() > 1 && netConsensus(c[0]) > netConsensus(c[1]));
}

}  // namespace core
}  // namespace fdml_localization
