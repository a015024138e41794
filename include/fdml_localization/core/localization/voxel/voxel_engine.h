/**
 * @file voxel_engine.h
 * @brief The voxel engine: the paper's voxel clouds with counting instead of subset
 *        enumeration, automatic k' (maximum consensus), per-candidate inlier masks and a
 *        continuous polish; plus the paper's and the FDML baseline's semantics for comparison.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/bound_windows.h"
#include "fdml_localization/core/localization/voxel/distance_table.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief The voxel engine. Per call: (1) the preimage of each reading, conservative: voxel v is
 *        in it when d lies within the bounds of h (cell_bounds.h) over every sensor pose
 *        v (+) g can take, widened by tau (bit-packed sets; docs/METHOD.md); (2) the count field
 *        (uint8 per voxel), M_k' = {count >= k'}, which always holds the truth's voxel; (3) seeds.
 *        Robust method, level by level from k down: the maximal hypotheses of the seeding's
 *        sample preimages (hypothesis_seeds.h) and the regional maxima of their dilated count,
 *        each refined by refineSeed() (exact ray casts, robust polish) once at least level - 2
 *        readings roughly agree at its centroid; in automatic mode k' is the first level some
 *        seed reaches net of contradicted readings (betterCandidate()), and the seeds that
 *        promised one level more get second chances (lattice search, other plateau voxels);
 *        supports are the sizes of the seeds' components of M_k'. Paper and baseline methods:
 *        the circular-mean centres of the components of M_k' (26-neighbour, periodic theta),
 *        the eps filter, delta uniqueness.
 *        Ranking and duplicate removal: rankAndDeduplicate().
 */
class VoxelEngine : public LocalizerEngine
{
public:
  /// @throws std::invalid_argument for a map with no area or a resolution out of range.
  VoxelEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options);

  /// Builds the distance table, or loads it from options.cache_dir.
  void prepare() override;
  /// @p readings must already be checked (validateReadings()).
  Result localize(const std::vector<Reading>& readings) override;

  const GridSpec& grid() const
  {
    return spec_;
  }
  /// The distance table (prepares on first use).
  const DistanceTable& table();
  /// How the table was obtained, and why a cache file was rejected (empty when it was not).
  TableSource tableSource() const
  {
    return table_source_;
  }
  const std::string& cacheMessage() const
  {
    return cache_message_;
  }

  /// Half-width tau of the band [d - tau, d + tau] the preimages test around the bounds of h [m].
  double preimageBand() const;

  /**
   * @brief The conservative preimage of one reading (cone readings included): voxel v is in it
   *        whenever some pose in v explains the reading within tau. Prepares on first use.
   */
  VoxelSet rawPreimage(const Reading& reading);
  /// The conservative preimages of a batch, one per reading.
  std::vector<VoxelSet> preimages(const std::vector<Reading>& readings);
  /**
   * @brief The same, also returning the seeding's sample preimages in @p raw: voxel v is in one
   *        when the 8 samples of h around (centre of v) (+) g take values on both sides of
   *        [d - b, d + b] or inside it, b = tau + half a cell (not conservative: seeding only;
   *        a cone reading's is its conservative preimage).
   */
  std::vector<VoxelSet> preimages(const std::vector<Reading>& readings, std::vector<VoxelSet>& raw);
  /**
   * @brief The paper's preimages (docs/METHOD.md, section 2), the paper and baseline methods'
   *        test: the sample preimages (see preimages()) dilated by one voxel, its completeness
   *        heuristic. Not conservative: those methods prove no bound (Certificate).
   */
  std::vector<VoxelSet> paperPreimages(const std::vector<Reading>& readings);
  /// count[v] = number of sets holding voxel v (at most 255 sets).
  void countField(const std::vector<VoxelSet>& sets, std::vector<std::uint8_t>& count) const;

  /// The count field and the preimages of the last localize() call: conservative with the robust
  /// method, the paper's (paperPreimages()) with the paper and baseline methods.
  const std::vector<std::uint8_t>& lastCount() const
  {
    return count_;
  }
  const std::vector<VoxelSet>& lastPreimages() const
  {
    return sets_;
  }
  /// The seeding's sample preimages and their count (seeding only).
  const std::vector<std::uint8_t>& lastRawCount() const
  {
    return raw_count_;
  }
  const std::vector<VoxelSet>& lastRawPreimages() const
  {
    return raw_sets_;
  }
  /// The seeding's sample preimages dilated by one voxel, and their count (count peaks).
  const std::vector<std::uint8_t>& lastSeedCount() const
  {
    return seed_count_;
  }
  const std::vector<VoxelSet>& lastSeedPreimages() const
  {
    return seed_sets_;
  }
  /// OpenMP threads of a call (options.threads, or all cores).
  int threads() const;
  /// Per set: whether it holds @p voxel.
  std::vector<bool> membership(std::size_t voxel, const std::vector<VoxelSet>& sets) const;

private:
  /// Heading cells [first, first + count) relative to the voxel's heading cell.
  struct ThetaWindow
  {
    int first = 0;
    int count = 0;
  };
  /// What the preimage test of one reading reads: the band and the heading windows.
  struct PreimagePlan
  {
    std::uint16_t lo = 0;  ///< d - tau (no return: max_range - tau), in the windows' RangeSteps
    std::uint16_t hi = 0;  ///< d + tau, in the windows' RangeSteps
    bool no_return = false;
    ThetaWindow ray;    ///< the cells the sensor headings cover
    ThetaWindow lower;  ///< the cells any ray of a cone reading may point in
    ThetaWindow inner;  ///< cells inside every cone of the voxel (count 0: none)
  };
  /// False when no voxel can be in the preimage (an offset far outside the grid).
  bool preimagePlan(const Reading& reading, PreimagePlan& plan) const;
  void prepareWindows(const std::vector<Reading>& readings);
  /// The seeding's sample test (not conservative): h - d changes sign among the 8 samples around
  /// (voxel centre) (+) g, band tau + half a cell.
  /// preimages() into @p sets and @p raw, whose sets' storage is reused (each heading slice
  /// cleared by the thread that fills it).
  void preimagesInto(const std::vector<Reading>& readings, std::vector<VoxelSet>& sets, std::vector<VoxelSet>& raw);
  void fillSampleSlice(const Reading& reading, int it, VoxelSet& set) const;
  void fillPreimageSlice(const Reading& reading, int it, VoxelSet& set) const;
  void localizeRobust(const std::vector<Reading>& readings, Result& result);
  void localizeComponentCentres(const std::vector<Reading>& readings, int min_inliers, Result& result);
  /// Clears from @p set the voxels whose cell lies wholly outside the search region.
  void keepRegion(VoxelSet& set) const;

  std::shared_ptr<const MapRayCaster> map_;
  LocalizerOptions options_;
  GridSpec spec_;
  DistanceTable table_;
  BoundWindows windows_;
  /// Voxels whose cell may meet the search region (every heading); empty without a region.
  VoxelSet region_mask_;
  bool prepared_ = false;
  double prepare_seconds_ = 0.0;
  bool prepare_reported_ = false;
  TableSource table_source_ = TableSource::Built;
  std::string cache_message_;
  std::vector<VoxelSet> sets_;
  std::vector<VoxelSet> raw_sets_;
  std::vector<std::uint8_t> count_;
  std::vector<std::uint8_t> raw_count_;  ///< count of the raw preimages (seeding only)
  std::vector<VoxelSet> seed_sets_;      ///< the raw preimages dilated (seeding only)
  std::vector<std::uint8_t> seed_count_;
};

}  // namespace core
}  // namespace fdml_localization
