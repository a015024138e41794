// The adaptive engine's last look at the places its seeds missed (region_fill.h).
#include "fdml_localization/core/localization/adaptive/region_fill.h"

#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/Cholesky>

#include <algorithm>
#include <cmath>
#include <iterator>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Leaves without a candidate (spread over them) whose centre pose is verified.
constexpr std::size_t kFillLeaves = 20000;
/// ... whose lattice is searched, the best centres first, when the centre explains at most this
/// many readings fewer than the best candidate ...
constexpr int kCentreSlack = 2;
/// ... at most this many leaves.
constexpr int kFillTries = 16;
/// A leaf's centre within this squared Mahalanobis distance of a candidate is its (chi-square,
/// 3 degrees of freedom, 99 %).
constexpr double kChiSquare3Dof = 11.34;

/// True when @p pose lies in @p box grown by @p margin [m] and @p angle [rad] (theta periodic).
bool nearBox(const PoseBox& box, const Pose2& pose, double margin, double angle)
{
  const double t = box.t0 + std::remainder(pose.theta - box.t0, kTwoPi);
  const auto within = [&](double a) { return a >= box.t0 - angle && a <= box.t1 + angle; };
  return pose.x >= box.x0 - margin && pose.x <= box.x1 + margin && pose.y >= box.y0 - margin &&
         pose.y <= box.y1 + margin && (within(t) || within(t + kTwoPi) || within(t - kTwoPi));
}

/// True when @p candidate accounts for the poses of @p box: its pose near the box
/// (uniqueness margins), or the box's centre within its covariance's 3 sigma (a continuum).
bool accountsFor(const Candidate& candidate, const PoseBox& box, const LocalizerOptions& options, double cell_xy,
                 double cell_theta)
{
  if (nearBox(box, candidate.pose, options.uniqueness_distance, options.uniqueness_angle))
  {
    return true;
  }
  const Pose2 centre(0.5 * (box.x0 + box.x1), 0.5 * (box.y0 + box.y1), 0.5 * (box.t0 + box.t1));
  const Eigen::Vector3d d = poseDifference(centre, candidate.pose);
  const Eigen::Matrix3d spread =
      candidate.covariance +
      Eigen::Vector3d(cell_xy * cell_xy, cell_xy * cell_xy, cell_theta * cell_theta).asDiagonal().toDenseMatrix();
  return d.dot(spread.ldlt().solve(d)) <= kChiSquare3Dof;
}

/// A leaf no candidate accounts for, with its centre pose's net consensus.
struct OpenLeaf
{
  const LeafBox* leaf;
  Candidate centre;
};

/// The leaves reaching @p target that no candidate accounts for (at most kFillLeaves, spread
/// over them), each with its centre verified, best centre first.
std::vector<OpenLeaf> openLeaves(const MapRayCaster& map, const std::vector<LeafBox>& leaves, int target,
                                 const std::vector<Reading>& readings, const std::vector<Candidate>& candidates,
                                 const LocalizerOptions& options)
{
  std::vector<const LeafBox*> reaching;
  for (const LeafBox& leaf : leaves)
  {
    if (leaf.count >= target)
    {
      reaching.push_back(&leaf);
    }
  }
  const std::size_t step = std::max<std::size_t>(1, reaching.size() / kFillLeaves);
  std::vector<OpenLeaf> open;
  for (std::size_t l = 0; l < reaching.size(); l += step)
  {
    const PoseBox& b = reaching[l]->box;
    if (std::any_of(candidates.begin(), candidates.end(),
                    [&](const Candidate& c) { return accountsFor(c, b, options, b.x1 - b.x0, b.t1 - b.t0); }))
    {
      continue;
    }
    const Pose2 centre(0.5 * (b.x0 + b.x1), 0.5 * (b.y0 + b.y1), 0.5 * (b.t0 + b.t1));
    Candidate c = verifiedCandidate(map, centre, readings, options.agreement_tolerance);
    if (netConsensus(c) >= target - kCentreSlack)
    {
      open.push_back(OpenLeaf{ reaching[l], std::move(c) });
    }
  }
  std::stable_sort(open.begin(), open.end(),
                   [](const OpenLeaf& a, const OpenLeaf& b) { return betterCandidate(a.centre, b.centre); });
  return open;
}

/// The best pose of @p leaf's lattice (leafLatticeBests()), refined and kept when the refinement
/// stays within two leaves of its start (the polish may slide far along a continuum).
Candidate placeInLeaf(const MapRayCaster& map, const LeafBox& leaf, const std::vector<Reading>& readings,
                      const LocalizerOptions& options, const RefinementSettings& settings)
{
  Candidate best = leafLatticeBests(map, { &leaf }, 1, readings, options.agreement_tolerance).front();
  Candidate c = refineSeed(map, best.pose, readings, best.inlier_mask, settings);
  const Eigen::Vector3d moved = poseDifference(c.pose, best.pose);
  const bool near = moved.head<2>().norm() <= 2.0 * (leaf.box.x1 - leaf.box.x0) &&
                    std::abs(moved.z()) <= 2.0 * (leaf.box.t1 - leaf.box.t0);
  return near && betterCandidate(c, best) ? c : best;
}

}  // namespace

std::vector<Candidate> leafLatticeBests(const MapRayCaster& map, const std::vector<const LeafBox*>& leaves,
                                        std::size_t max_leaves, const std::vector<Reading>& readings, double eps)
{
  const std::size_t step = std::max<std::size_t>(1, leaves.size() / std::max<std::size_t>(1, max_leaves));
  const auto at = [](double lo, double hi, int j) { return lo + (hi - lo) * (j + 0.5) / kLeafLattice; };
  std::vector<Candidate> lattice_best;
  for (std::size_t l = 0; l < leaves.size(); l += step)
  {
    const PoseBox& b = leaves[l]->box;
    Candidate leaf_best;
    leaf_best.inliers = -1;
    for (int i = 0; i < kLeafLattice * kLeafLattice * kLeafLattice; ++i)
    {
      const Pose2 pose(at(b.x0, b.x1, i % kLeafLattice), at(b.y0, b.y1, (i / kLeafLattice) % kLeafLattice),
                       at(b.t0, b.t1, i / (kLeafLattice * kLeafLattice)));
      Candidate c = verifiedCandidate(map, pose, readings, eps);
      if (leaf_best.inliers < 0 || betterCandidate(c, leaf_best))
      {
        leaf_best = std::move(c);
      }
    }
    lattice_best.push_back(std::move(leaf_best));
  }
  return lattice_best;
}

int fillUncoveredRegions(const MapRayCaster& map, const std::vector<LeafBox>& leaves,
                         const std::vector<Reading>& readings, const LocalizerOptions& options,
                         const RefinementSettings& settings, Result& result)
{
  if (result.candidates.empty())
  {
    return 0;
  }
  const int target = netConsensus(result.candidates.front());
  const std::vector<OpenLeaf> open = openLeaves(map, leaves, target, readings, result.candidates, options);
  std::vector<Candidate> added;
  int tried = 0;
  for (std::size_t i = 0; i < open.size() && tried < kFillTries; ++i)
  {
    const PoseBox& b = open[i].leaf->box;
    const double cx = b.x1 - b.x0, ct = b.t1 - b.t0;
    if (std::any_of(added.begin(), added.end(), [&](const Candidate& c) { return accountsFor(c, b, options, cx, ct); }))
    {
      continue;
    }
    ++tried;
    Candidate place = placeInLeaf(map, *open[i].leaf, readings, options, settings);
    if (netConsensus(place) >= target)
    {
      place.support = 1.0;
      widenAlongContinua(map, readings, settings.noise_sigma, place);
      added.push_back(std::move(place));
    }
  }
  if (!added.empty())
  {
    std::move(added.begin(), added.end(), std::back_inserter(result.candidates));
    result.candidates = rankAndDeduplicate(std::move(result.candidates), options.uniqueness_distance,
                                           options.uniqueness_angle, options.max_candidates);
  }
  return tried;
}

}  // namespace core
}  // namespace fdml_localization
