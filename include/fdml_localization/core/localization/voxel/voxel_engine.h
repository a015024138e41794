/**
 * @file voxel_engine.h
 * @brief The voxel engine: the paper's voxel clouds with counting instead of subset
 *        enumeration, automatic k' (maximum consensus), per-candidate inlier masks and a
 *        continuous polish; plus the paper's and the FDML baseline's semantics for comparison.
 */
#pragma once

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
 * @brief The voxel engine. Per call: (1) the preimage of each reading by the sign-change test
 *        on the distance table's 2 x 2 x 2 sample blocks, then a one-voxel dilation (bit-packed
 *        sets); (2) the count field (uint8 per voxel), M_k' = {count >= k'}; (3) seeds.
 *        Robust method, level by level from k down: the maximal hypotheses of the raw
 *        preimages (hypothesis_seeds.h) and the regional maxima of the dilated count field,
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

  /**
   * @brief Half-width b of the band [d - b, d + b] the preimages test [m]: the range tolerance
   *        tau plus half a cell, because where a ray hits near a concave corner h peaks between
   *        samples, above all of them, by up to about half a cell times the slope difference.
   */
  double preimageBand() const;

  /**
   * @brief The voxel preimage of one reading before dilation: voxel v is in it when the
   *        samples of h around (centre of v) (+) g take values on both sides of [d - b, d + b]
   *        or inside it (for d = +inf: some sample exceeds max_range - b), b = preimageBand().
   *        Prepares on first use.
   */
  VoxelSet rawPreimage(const Reading& reading);
  /// The dilated preimages of a batch, one per reading.
  std::vector<VoxelSet> preimages(const std::vector<Reading>& readings);
  /// The same, also returning the preimages before dilation in @p raw.
  std::vector<VoxelSet> preimages(const std::vector<Reading>& readings, std::vector<VoxelSet>& raw);
  /// count[v] = number of sets holding voxel v (at most 255 sets).
  void countField(const std::vector<VoxelSet>& sets, std::vector<std::uint8_t>& count) const;

  /// The count field and the dilated preimages of the last localize() call.
  const std::vector<std::uint8_t>& lastCount() const
  {
    return count_;
  }
  const std::vector<VoxelSet>& lastPreimages() const
  {
    return sets_;
  }
  /// The same before dilation (seeding only).
  const std::vector<std::uint8_t>& lastRawCount() const
  {
    return raw_count_;
  }
  const std::vector<VoxelSet>& lastRawPreimages() const
  {
    return raw_sets_;
  }
  /// OpenMP threads of a call (options.threads, or all cores).
  int threads() const;
  /// Per set: whether it holds @p voxel.
  std::vector<bool> membership(std::size_t voxel, const std::vector<VoxelSet>& sets) const;

private:
  void fillPreimageSlice(const Reading& reading, int it, VoxelSet& set) const;
  void localizeRobust(const std::vector<Reading>& readings, Result& result);
  void localizeComponentCentres(const std::vector<Reading>& readings, int min_inliers, Result& result);

  std::shared_ptr<const MapRayCaster> map_;
  LocalizerOptions options_;
  GridSpec spec_;
  DistanceTable table_;
  bool prepared_ = false;
  double prepare_seconds_ = 0.0;
  bool prepare_reported_ = false;
  TableSource table_source_ = TableSource::Built;
  std::string cache_message_;
  std::vector<VoxelSet> sets_;
  std::vector<VoxelSet> raw_sets_;
  std::vector<std::uint8_t> count_;
  std::vector<std::uint8_t> raw_count_;  ///< count of the raw preimages (seeding only)
};

}  // namespace core
}  // namespace fdml_localization
