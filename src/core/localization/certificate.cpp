// The certificate of an answer: the proved consensus bound and the regions reaching it.
#include "fdml_localization/core/localization/certificate.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/adaptive/leaf_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/level_masks.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Halvings of every axis a region's boxes get before the region counts as not excluded.
constexpr int kExclusionDepth = 3;
/// Box tests the exclusion of all regions may spend.
constexpr long kExclusionBudget = 20000;

/// The boxes reaching the bound, with the region each belongs to.
struct BoundRegions
{
  int count = 0;
  std::vector<PoseBox> boxes;
  std::vector<int> region;  ///< per box
};

/// The readings the best candidate explains (0 without candidates).
int bestConsensus(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance, const Result& result)
{
  return result.candidates.empty() ? 0 : consensusWithin(map, result.candidates.front().pose, readings, tolerance);
}

/// Fills @p result.certificate (@p best: bestConsensus()): covered regions hold a candidate's
/// pose; the others are excluded when no sub-box of theirs may reach the bound.
void certify(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance, int bound, int best,
             const BoundRegions& regions, bool unresolved, Result& result)
{
  Certificate& c = result.certificate;
  c.max_consensus_bound = bound;
  c.best_consensus = best;
  c.regions_at_bound = regions.count;
  std::vector<char> covered(static_cast<std::size_t>(regions.count), 0);
  for (std::size_t b = 0; b < regions.boxes.size(); ++b)
  {
    for (const Candidate& candidate : result.candidates)
    {
      covered[static_cast<std::size_t>(regions.region[b])] |= regions.boxes[b].contains(candidate.pose) ? 1 : 0;
    }
  }
  c.regions_covered = static_cast<int>(std::count(covered.begin(), covered.end(), 1));
  if (bound < 0 || c.best_consensus != bound || unresolved)
  {
    return;  // the certificate is incomplete whatever the other regions hold
  }
  std::vector<char> reachable(covered.size(), 0);
  long budget = kExclusionBudget;
  for (std::size_t b = 0; b < regions.boxes.size(); ++b)
  {
    const std::size_t r = static_cast<std::size_t>(regions.region[b]);
    if (!covered[r] && !reachable[r])
    {
      PoseBox sub_box;  // which sub-box reaches does not matter here
      const bool reaches =
          firstSubBoxReaching(map, readings, tolerance, regions.boxes[b], bound, kExclusionDepth, budget, sub_box);
      reachable[r] = reaches ? 1 : 0;
    }
  }
  c.regions_excluded =
      regions.count - c.regions_covered - static_cast<int>(std::count(reachable.begin(), reachable.end(), 1));
  c.complete = c.regions_covered + c.regions_excluded == regions.count;
}

/// The voxels of @p spec whose (closed) box holds one of @p candidates' poses, in no order.
std::vector<std::size_t> voxelsHolding(const GridSpec& spec, const std::vector<Candidate>& candidates)
{
  std::vector<std::size_t> voxels;
  for (const Candidate& candidate : candidates)
  {
    const Pose2& p = candidate.pose;
    const double fx = std::floor((p.x - spec.origin_x) / spec.cell);
    const double fy = std::floor((p.y - spec.origin_y) / spec.cell);
    const double ft = std::floor((wrapAngle(p.theta) + kPi) / spec.thetaStep());
    if (!(fx >= -1.0 && fx <= spec.nx && fy >= -1.0 && fy <= spec.ny && ft >= -1.0 && ft <= spec.nt))
    {
      continue;  // outside the grid (or not finite)
    }
    // A closed box holds a pose on its border too: the cells next to the one computed.
    for (int it = static_cast<int>(ft) - 1; it <= static_cast<int>(ft) + 1; ++it)
    {
      for (int iy = std::max(static_cast<int>(fy) - 1, 0); iy <= std::min(static_cast<int>(fy) + 1, spec.ny - 1); ++iy)
      {
        for (int ix = std::max(static_cast<int>(fx) - 1, 0); ix <= std::min(static_cast<int>(fx) + 1, spec.nx - 1);
             ++ix)
        {
          const std::size_t v = spec.index(ix, iy, (it + spec.nt) % spec.nt);
          if (voxelBox(spec, v).contains(p))
          {
            voxels.push_back(v);
          }
        }
      }
    }
  }
  return voxels;
}
}  // namespace

int consensusWithin(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings, double tolerance)
{
  int count = 0;
  for (const Reading& reading : readings)
  {
    // NaN (the sensor in a wall) fails the comparison.
    count += std::abs(readingResidual(map, pose, reading)) <= tolerance ? 1 : 0;
  }
  return count;
}

void certifyAdaptive(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance,
                     const AdaptiveSearch& search, std::int64_t theta_cells, Result& result)
{
  const int bound = search.consensusBound();
  const std::vector<LeafBox>& leaves = search.result().leaves;
  BoundRegions regions;
  const std::vector<int> labels = leafComponents(leaves, bound, theta_cells, regions.count);
  for (std::size_t i = 0; i < leaves.size(); ++i)
  {
    if (labels[i] >= 0)
    {
      regions.boxes.push_back(leaves[i].box);
      regions.region.push_back(labels[i]);
    }
  }
  certify(map, readings, tolerance, bound, bestConsensus(map, readings, tolerance, result), regions,
          search.unresolvedReaches(bound), result);
}

void certifyVoxels(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance,
                   const GridSpec& spec, const std::vector<std::uint8_t>& count, Result& result)
{
  const int bound = count.empty() ? -1 : *std::max_element(count.begin(), count.end());
  const int best = bestConsensus(map, readings, tolerance, result);
  if (bound > 0 && best != bound)
  {
    // Incomplete whatever the regions hold (certify()): only how many there are and how many
    // hold a candidate, from bit masks, without listing their voxels.
    Certificate& c = result.certificate;
    c.max_consensus_bound = bound;
    c.best_consensus = best;
    std::size_t holding = 0;
    c.regions_at_bound = static_cast<int>(
        LevelMasks(spec, count, bound).componentCount(voxelsHolding(spec, result.candidates), holding));
    c.regions_covered = static_cast<int>(holding);
    return;
  }
  BoundRegions regions;
  if (bound > 0)
  {
    const std::vector<VoxelCluster> clusters = connectedComponents(spec, count, bound);
    regions.count = static_cast<int>(clusters.size());
    for (std::size_t c = 0; c < clusters.size(); ++c)
    {
      for (const std::size_t v : clusters[c].voxels)
      {
        regions.boxes.push_back(voxelBox(spec, v));
        regions.region.push_back(static_cast<int>(c));
      }
    }
  }
  certify(map, readings, tolerance, bound, best, regions, false, result);
}

}  // namespace core
}  // namespace fdml_localization
