/**
 * @file adaptive_engine.h
 * @brief The adaptive engine: branch and prune over pose boxes (adaptive_search.h) down to
 *        the target resolution, then the same seeds, verification, polish, de-duplication and
 *        ranking as the voxel engine. Needs no precomputed table, so its cost grows with the
 *        answer rather than with the map's area times the resolution.
 */
#pragma once

#include "fdml_localization/core/adaptive_search.h"
#include "fdml_localization/core/localizer.h"

#include <memory>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A cluster of surviving leaves: its peak-count plateau gives one seed.
struct LeafCluster
{
  Pose2 centroid;           ///< mean x, y [m], circular mean theta [rad] of the plateau leaves
  std::size_t representative = 0;  ///< index (into the leaves) of the plateau leaf nearest the centroid
  std::size_t size = 0;     ///< leaves in the whole connected component
  int peak_count = 0;
};

/**
 * @brief Connected components (26 neighbours on the leaf lattice, periodic in theta with
 *        @p theta_cells cells) of the leaves with count >= @p level; each component yields one
 *        cluster per connected plateau of its peak count (peaks are never averaged together).
 */
std::vector<LeafCluster> clusterLeaves(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells);

class AdaptiveEngine : public LocalizerEngine
{
public:
  AdaptiveEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options);
  void prepare() override {}
  Result localize(const std::vector<Reading>& readings) override;

  /// The box-search settings used for a given k'.
  AdaptiveSearchOptions searchOptions(int min_count) const;

private:
  std::shared_ptr<const MapRayCaster> map_;
  LocalizerOptions options_;
  double cell_xy_;     ///< leaf size [m]
  double cell_theta_;  ///< leaf size [rad]
};

}  // namespace core
}  // namespace fdml_localization
