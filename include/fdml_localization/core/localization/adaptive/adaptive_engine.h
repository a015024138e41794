/**
 * @file adaptive_engine.h
 * @brief The adaptive engine: branch and prune over pose boxes (adaptive_search.h) down to
 *        the target resolution, then the same seeds, verification, polish, de-duplication and
 *        ranking as the voxel engine. Needs no precomputed table, so its cost grows with the
 *        answer rather than with the map's area times the resolution.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <memory>
#include <vector>

namespace fdml_localization
{
namespace core
{
class AdaptiveEngine : public LocalizerEngine
{
public:
  AdaptiveEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options);
  void prepare() override
  {}
  Result localize(const std::vector<Reading>& readings) override;

  /// The leaves of the last localize() call's search (for tests and diagnostics).
  const std::vector<LeafBox>& lastLeaves() const
  {
    return last_leaves_;
  }

  /// The box-search settings used for a given k'.
  AdaptiveSearchOptions searchOptions(int min_count) const;

private:
  /// The robust method: regional maxima per k' from k down, polished seeds, retries.
  void localizeRobust(AdaptiveSearch& search, const std::vector<Reading>& readings, Result& result);
  /// The paper's and the baseline's semantics: one k', verified component centres.
  void localizeFixed(AdaptiveSearch& search, const std::vector<Reading>& readings, int level, Result& result);
  /// Where the readings hold a no-return one and the best candidate explains fewer readings than
  /// the search's bound: a lattice of poses in the leaves at the bound verified exactly, the best
  /// added when it beats the best candidate. The polish moves poses by finite ranges only, so a
  /// region that no-return readings shape is searched rather than polished.
  void searchNoReturnRegion(const AdaptiveSearch& search, const std::vector<Reading>& readings, Result& result) const;

  std::shared_ptr<const MapRayCaster> map_;
  LocalizerOptions options_;
  double cell_xy_;     ///< leaf size [m]
  double cell_theta_;  ///< leaf size [rad]
  std::shared_ptr<const BoxOccupancy> occupancy_;
  /// The search region's cells (null without one): AdaptiveSearchOptions::positions.
  std::shared_ptr<const BoxOccupancy> region_occupancy_;
  std::vector<LeafBox> last_leaves_;  ///< built once per map
  /// Cap on the occupancy grid's cells per side (two 4-byte tables: 2048^2 cells = 34 MB).
  static constexpr int kOccupancyCells = 2048;
};

}  // namespace core
}  // namespace fdml_localization
