// The adaptive engine's last look at the places its seeds missed (region_fill.h).
#include "fdml_localization/core/localization/adaptive/region_fill.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
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
/// Leaves at the best consensus (spread over them) checked; those no candidate accounts for
/// get their centre pose verified ...
constexpr std::size_t kFillLeaves = 20000;
/// ... whose lattice is searched, region by region (round robin, the best centres first) while
/// no place was found in the region, or when the centre explains at most this many readings
/// fewer than the best candidate ...
constexpr int kCentreSlack = 2;
/// ... at most this many leaves.
constexpr int kFillTries = 64;
/// A leaf's centre within this squared Mahalanobis distance of a candidate is its (chi-square,
/// 3 degrees of freedom, 99 %).
constexpr double kChiSquare3Dof = 11.34;

/// What candidates account for: a leaf box holding a candidate's pose within the uniqueness
/// margins, or whose centre lies within 3 sigma of the candidate's covariance grown by the leaf's
/// size (a continuum). The grown covariance is factorised once per candidate and leaf size.
class Accounting
{
public:
  explicit Accounting(const LocalizerOptions& options) : options_(options)
  {}

  void add(const Candidate& candidate)
  {
    // Factorised here too so that it is never read uninitialised; a leaf size replaces it.
    entries_.push_back(
        Entry{ candidate.pose, candidate.covariance, Eigen::LDLT<Eigen::Matrix3d>(candidate.covariance), -1.0, -1.0 });
  }

  bool accountsFor(const PoseBox& box)
  {
    const double cx = box.x1 - box.x0, ct = box.t1 - box.t0;
    const Pose2 centre = box.centre();
    for (Entry& e : entries_)
    {
      if (box.contains(e.pose, options_.uniqueness_distance, options_.uniqueness_angle))
      {
        return true;
      }
      if (cx != e.cell_xy || ct != e.cell_theta)
      {
        e.cell_xy = cx;
        e.cell_theta = ct;
        e.spread.compute(e.covariance + Eigen::Vector3d(cx * cx, cx * cx, ct * ct).asDiagonal().toDenseMatrix());
      }
      const Eigen::Vector3d d = poseDifference(centre, e.pose);
      if (d.dot(e.spread.solve(d)) <= kChiSquare3Dof)
      {
        return true;
      }
    }
    return false;
  }

private:
  struct Entry
  {
    Pose2 pose;
    Eigen::Matrix3d covariance;
    Eigen::LDLT<Eigen::Matrix3d> spread;  ///< of covariance + the leaf size below, squared
    double cell_xy, cell_theta;           ///< [m], [rad]
  };
  const LocalizerOptions& options_;
  std::vector<Entry> entries_;
};

/// A leaf no candidate accounts for, with its centre pose's net consensus and its region.
struct OpenLeaf
{
  const LeafBox* leaf;
  Candidate centre;
  int region;  ///< label of its connected region of leaves reaching the target
  int rank;    ///< 0 for its region's best centre, 1 for the next, ...
};

/// The leaves reaching @p target that no candidate accounts for (at most kFillLeaves, spread
/// over them), each with its centre verified, in the order they are searched: round robin over
/// their connected regions (the best leaf of every region, then the second best, ...; the best
/// centres first within a rank): a region's place may lie far from its leaves' centres, and on a
/// large map many separate regions reach the consensus (alike rooms, alcoves).
std::vector<OpenLeaf> openLeaves(const MapRayCaster& map, const std::vector<LeafBox>& leaves, int target,
                                 std::int64_t theta_cells, const std::vector<Reading>& readings,
                                 const std::vector<Candidate>& candidates, const LocalizerOptions& options)
{
  Accounting accounting(options);
  for (const Candidate& c : candidates)
  {
    accounting.add(c);
  }
  int regions = 0;
  const std::vector<int> labels = leafComponents(leaves, target, theta_cells, regions);
  std::vector<std::size_t> reaching;
  for (std::size_t l = 0; l < leaves.size(); ++l)
  {
    if (labels[l] >= 0)
    {
      reaching.push_back(l);
    }
  }
  const std::size_t step = std::max<std::size_t>(1, reaching.size() / kFillLeaves);
  std::vector<OpenLeaf> open;
  for (std::size_t j = 0; j < reaching.size(); j += step)
  {
    const LeafBox& leaf = leaves[reaching[j]];
    if (!accounting.accountsFor(leaf.box))
    {
      open.push_back(OpenLeaf{ &leaf, verifiedCandidate(map, leaf.box.centre(), readings, options.agreement_tolerance),
                               labels[reaching[j]], 0 });
    }
  }
  std::stable_sort(open.begin(), open.end(),
                   [](const OpenLeaf& a, const OpenLeaf& b) { return betterCandidate(a.centre, b.centre); });
  std::vector<int> ranked(static_cast<std::size_t>(regions), 0);
  for (OpenLeaf& o : open)
  {
    o.rank = ranked[static_cast<std::size_t>(o.region)]++;
  }
  std::stable_sort(open.begin(), open.end(), [](const OpenLeaf& a, const OpenLeaf& b) { return a.rank < b.rank; });
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

RefinementSettings latticeRefinement(const LocalizerOptions& options, double cell_xy, double cell_theta)
{
  RefinementSettings settings;
  settings.agreement_tolerance = options.agreement_tolerance;
  settings.robust_scale = std::max(options.agreement_tolerance, cell_xy);
  settings.seed_position_error = cell_xy;
  settings.seed_angle_error = cell_theta;
  return settings;
}

int fillUncoveredRegions(const MapRayCaster& map, const std::vector<LeafBox>& leaves, std::int64_t theta_cells,
                         const std::vector<Reading>& readings, const LocalizerOptions& options,
                         const RefinementSettings& settings, Result& result)
{
  if (result.candidates.empty())
  {
    return 0;
  }
  const int target = netConsensus(result.candidates.front());
  const std::vector<OpenLeaf> open = openLeaves(map, leaves, target, theta_cells, readings, result.candidates, options);
  std::vector<Candidate> added;
  Accounting found(options);  // the open leaves' places found so far
  int regions = 0;
  for (const OpenLeaf& o : open)
  {
    regions = std::max(regions, o.region + 1);
  }
  std::vector<char> placed(static_cast<std::size_t>(regions), 0);  // per region: a place was found in it
  int tried = 0;
  for (std::size_t i = 0; i < open.size() && tried < kFillTries; ++i)
  {
    const OpenLeaf& o = open[i];
    const bool promising = netConsensus(o.centre) >= target - kCentreSlack;
    if (found.accountsFor(o.leaf->box) || (placed[static_cast<std::size_t>(o.region)] && !promising))
    {
      continue;
    }
    ++tried;
    Candidate place = placeInLeaf(map, *o.leaf, readings, options, settings);
    if (netConsensus(place) >= target)
    {
      placed[static_cast<std::size_t>(o.region)] = 1;
      place.support = 1.0;
      widenAlongContinua(map, readings, settings.noise_sigma, place);
      found.add(place);
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
