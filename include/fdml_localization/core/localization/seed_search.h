/**
 * @file seed_search.h
 * @brief The one robust search both engines share. An engine supplies seeds level by level
 *        (voxels or boxes that explain `level` readings, from k down); this search verifies them,
 *        refines each once (robust_search.h: refineSeed), gives second chances to the seeds that
 *        promise more than they reached, picks k' (automatic: maximum net consensus; fixed:
 *        options.min_inliers) and ranks the candidates (ranking.h).
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/region_starts.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <cstddef>
#include <memory>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// One seed an engine supplies.
struct SearchSeed
{
  Pose2 start;                      ///< where refinement starts (the region's centre) [m, rad]
  std::vector<bool> hypothesis;     ///< per reading: the seed's region lies in its preimage
  int promised = 0;                 ///< readings the seed's region explains (its peak count)
  std::vector<Pose2> retry_starts;  ///< other poses of the region, for second chances
  /// Poses spread over the region, for the final multi-start of the candidate the seed gives
  /// (empty: retry_starts)
  std::vector<Pose2> region_starts;
  /// Every pose of a region larger than region_starts (voxel or leaf centres), shared by its
  /// seeds: where the final multi-start finds several optima tying at the best consensus, each
  /// agreeing one is polished (polishTiedCandidate()). Null: region_starts are all its poses.
  std::shared_ptr<const std::vector<Pose2>> region_poses;
  std::size_t region = 0;  ///< the engine's id of the seed's region (voxel, leaf cluster)
  double support = 0.0;    ///< size of the seed's region (voxels or boxes)
};

/// What an engine supplies to the robust search.
class SeedSource
{
public:
  virtual ~SeedSource() = default;
  /// The new seeds that explain exactly @p level readings; called for level = k, k - 1, ...
  virtual std::vector<SearchSeed> seedsAt(int level) = 0;
  /// True when the engine can supply no more levels (a search budget ran out).
  virtual bool exhausted() const
  {
    return false;
  }
};

/// The outcome of robustSearch().
struct SeedSearchOutcome
{
  std::vector<Candidate> candidates;  ///< ranked best first, duplicates removed
  std::vector<std::size_t> regions;   ///< per candidate: SearchSeed::region of its seed
  int min_inliers_used = 3;           ///< k' used
};

/**
 * @brief The robust method over an engine's seeds: levels from k down to the lowest allowed
 *        k'; per level the new seeds are verified, refined once when their region promises the
 *        level and at least level - 2 readings roughly agree at their start; automatic k' stops
 *        at the first level some candidate reaches net of contradicted readings; fixed k' stops
 *        once max_candidates distinct candidates reach the level. Then second chances (a local
 *        lattice search and restarts from other poses of the region) one level above the
 *        consensus reached (automatic) or at k' when nothing reached it.
 * @param times the verification, components and polish stages are added to it
 */
SeedSearchOutcome robustSearch(SeedSource& source, const MapRayCaster& map, const std::vector<Reading>& readings,
                               const LocalizerOptions& options, const SeedScale& scale, StageTimes& times);

}  // namespace core
}  // namespace fdml_localization
