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
  std::vector<std::size_t> members;  ///< plateau leaves (leafMaxima only), ascending
};

/**
 * @brief Connected components (26 neighbours on the leaf lattice, periodic in theta with
 *        @p theta_cells cells) of the leaves with count >= @p level; each component yields one
 *        cluster per connected plateau of its peak count (peaks are never averaged together).
 */
std::vector<LeafCluster> clusterLeaves(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells);

/**
 * @brief Regional maxima at exactly @p level: connected plateaus (26 neighbours, periodic theta)
 *        of the leaves with count == level that touch no leaf with a higher count; largest first.
 */
std::vector<LeafCluster> leafMaxima(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells);

class AdaptiveEngine : public LocalizerEngine
{
public:
  AdaptiveEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options);
  void prepare() override {}
  Result localize(const std::vector<Reading>& readings) override;

  /// The leaves of the last localize() call's search (for tests and diagnostics).
  const std::vector<LeafBox>& lastLeaves() const { return last_leaves_; }

  /// The box-search settings used for a given k'.
  AdaptiveSearchOptions searchOptions(int min_count) const;

private:
  /// The robust method: regional maxima per k' from k down, polished seeds, retries.
  void localizeRobust(AdaptiveSearch& search, const std::vector<Reading>& readings, Result& result);
  /// The paper's and the baseline's semantics: one k', verified component centres.
  void localizeFixed(AdaptiveSearch& search, const std::vector<Reading>& readings, int level, Result& result);

  std::shared_ptr<const MapRayCaster> map_;
  LocalizerOptions options_;
  double cell_xy_;     ///< leaf size [m]
  double cell_theta_;  ///< leaf size [rad]
  std::shared_ptr<const BoxOccupancy> occupancy_;
  std::vector<LeafBox> last_leaves_;  ///< built once per map
  /// Cap on the occupancy grid's cells per side (two 4-byte tables: 2048^2 cells = 34 MB).
  static constexpr int kOccupancyCells = 2048;
};

}  // namespace core
}  // namespace fdml_localization
