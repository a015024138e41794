#include "fdml_localization/core/tracking/local_solve.h"

#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
std::vector<bool> maskOf(const LeafBox& leaf, std::size_t k)
{
  std::vector<bool> hypothesis(k, true);
  for (std::size_t i = 0; i < k && i < 64; ++i)
  {
    hypothesis[i] = ((leaf.mask >> i) & 1U) != 0;
  }
  return hypothesis;
}

bool near(const Pose2& a, const Pose2& b, double xy, double theta)
{
  return (a.position() - b.position()).norm() <= xy && std::abs(angleDiff(a.theta, b.theta)) <= theta;
}

/// The starts to refine: the box's centre (all readings), then the distinct leaves of the
/// highest counts, at most @p max_seeds of them.
std::vector<std::pair<Pose2, std::vector<bool>>> startsOf(std::vector<LeafBox> leaves, const PoseBox& box,
                                                          std::size_t k, const LocalSolveSettings& settings)
{
  std::vector<std::pair<Pose2, std::vector<bool>>> starts;
  starts.emplace_back(box.centre(), std::vector<bool>(k, true));
  std::stable_sort(leaves.begin(), leaves.end(), [](const LeafBox& a, const LeafBox& b) { return a.count > b.count; });
  const double xy = 2.0 * settings.cell_xy;
  const double theta = 2.0 * settings.cell_theta;
  for (const LeafBox& leaf : leaves)
  {
    if (static_cast<int>(starts.size()) > settings.max_seeds)
    {
      break;
    }
    const Pose2 centre = leaf.box.centre();
    const bool distinct =
        std::none_of(starts.begin() + 1, starts.end(), [&](const auto& s) { return near(s.first, centre, xy, theta); });
    if (distinct)
    {
      starts.emplace_back(centre, maskOf(leaf, k));
    }
  }
  return starts;
}
AdaptiveSearchOptions searchOptions(const PoseBox& box, const LocalSolveSettings& settings)
{
  AdaptiveSearchOptions options;
  options.cell_xy = settings.cell_xy;
  options.cell_theta = settings.cell_theta;
  options.min_count = settings.min_consensus;
  options.range_tolerance = settings.range_tolerance;
  options.max_boxes = settings.max_boxes;
  options.threads = 1;
  options.region = box;
  return options;
}

/// The shared refinement's settings for leaves of @p settings' size, with its prior.
RefinementSettings refinementOf(const LocalSolveSettings& settings)
{
  RefinementSettings refine;
  refine.agreement_tolerance = settings.agreement_tolerance;
  refine.robust_scale = std::max(settings.agreement_tolerance, settings.cell_xy);
  refine.seed_position_error = settings.cell_xy;
  refine.seed_angle_error = settings.cell_theta;
  refine.max_escapes = 1;
  refine.prior = settings.prior;
  return refine;
}
}  // namespace

bool onlyPlaceInRegion(const MapRayCaster& map, const BoxOccupancy& occupancy, const std::vector<Reading>& readings,
                       const PoseBox& region, const Pose2& pose, int consensus, double distance, double angle,
                       const LocalSolveSettings& settings)
{
  constexpr double kLeavesPerAxis = 128.0;
  LocalSolveSettings coarse = settings;
  coarse.cell_xy = std::max(settings.cell_xy, std::max(region.x1 - region.x0, region.y1 - region.y0) / kLeavesPerAxis);
  coarse.cell_theta = std::max(settings.cell_theta, (region.t1 - region.t0) / kLeavesPerAxis);
  coarse.min_consensus = consensus;
  const AdaptiveSearchResult found = adaptiveSearch(map, occupancy, readings, searchOptions(region, coarse));
  if (found.truncated)
  {
    return false;
  }
  // The box test is loose by about a leaf: a leaf within two leaves of the place's own region
  // may hold the place itself; one farther holds another place.
  return std::none_of(found.leaves.begin(), found.leaves.end(), [&](const LeafBox& leaf) {
    const Pose2 centre = leaf.box.centre();
    return (centre.position() - pose.position()).norm() > distance + 2.0 * coarse.cell_xy ||
           std::abs(angleDiff(centre.theta, pose.theta)) > angle + 2.0 * coarse.cell_theta;
  });
}

bool insideBox(const Pose2& pose, const PoseBox& box, double margin_xy, double margin_theta)
{
  const double centre_theta = 0.5 * (box.t0 + box.t1);
  const double half_theta = 0.5 * (box.t1 - box.t0);
  return pose.x >= box.x0 - margin_xy && pose.x <= box.x1 + margin_xy && pose.y >= box.y0 - margin_xy &&
         pose.y <= box.y1 + margin_xy && std::abs(angleDiff(pose.theta, centre_theta)) <= half_theta + margin_theta;
}

LocalSolveOutcome localSolve(const MapRayCaster& map, const BoxOccupancy& occupancy,
                             const std::vector<Reading>& readings, const PoseBox& box,
                             const LocalSolveSettings& settings)
{
  LocalSolveOutcome outcome;
  const int k = static_cast<int>(readings.size());
  outcome.best_consensus = -k;
  outcome.least_contradicted = k;
  const AdaptiveSearchResult found = adaptiveSearch(map, occupancy, readings, searchOptions(box, settings));
  outcome.truncated = found.truncated;
  for (const LeafBox& leaf : found.leaves)
  {
    outcome.best_possible = std::max(outcome.best_possible, leaf.count);
  }
  if (found.leaves.empty())
  {
    // No leaf may explain k' readings: say whether the prediction is contradicted or only hidden,
    // and what it explains (a place whose readings people hide keeps that much support).
    const PoseEvaluation centre = evaluatePose(map, box.centre(), readings, settings.agreement_tolerance);
    outcome.least_contradicted = centre.contradicted;
    outcome.best_consensus = centre.inliers - centre.contradicted;
    return outcome;
  }
  const RefinementSettings refine = refinementOf(settings);
  std::vector<Candidate> fixes;
  for (const auto& start : startsOf(found.leaves, box, readings.size(), settings))
  {
    Candidate c = refineSeed(map, start.first, readings, start.second, refine);
    outcome.best_consensus = std::max(outcome.best_consensus, netConsensus(c));
    outcome.least_contradicted = std::min(outcome.least_contradicted, c.contradicted);
    if (netConsensus(c) >= settings.min_consensus && insideBox(c.pose, box, settings.cell_xy, settings.cell_theta))
    {
      fixes.push_back(std::move(c));
      // The box's centre (the prediction) reached the most any leaf may explain: no start can
      // do better.
      if (fixes.size() == 1 && fixes[0].inliers >= outcome.best_possible && fixes[0].contradicted == 0)
      {
        break;
      }
    }
  }
  outcome.fixes =
      rankAndDeduplicate(std::move(fixes), 2.0 * settings.cell_xy, 2.0 * settings.cell_theta, settings.max_seeds + 1);
  // A fix at the end of a continuum of exact poses (a corridor's axis, a heading the readings
  // barely see) must not claim the polish's local precision: the tracker fuses it with the
  // prediction by these covariances. And a person in front of the one sensor fixing a direction
  // moves the fix with every reading explained: what the fix loses without any one direction's
  // readings goes to the publishing rule.
  for (Candidate& fix : outcome.fixes)
  {
    widenAlongContinua(map, readings, refine.noise_sigma, fix);
    outcome.direction_loss.push_back(settings.direction_group < 0.0 ?
                                         Eigen::Matrix3d::Zero() :
                                         oneDirectionLostCovariance(map, fix.pose, readings, fix.inlier_mask,
                                                                    refine.noise_sigma, settings.direction_group));
  }
  return outcome;
}

}  // namespace core
}  // namespace fdml_localization
