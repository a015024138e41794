/**
 * @file count_buckets.h
 * @brief The voxel engine's count fields level by level, for its robust search's seeds: the
 *        voxels of each count (CountBuckets), and the conservative field's regional maxima
 *        screened by the box test (ScreenedCount).
 */
#pragma once

#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/voxel/box_screen.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// The voxels of a count field by count (voxelsByCount()), each level bucketed when first asked
/// for: the low levels hold most voxels and are rarely reached.
class CountBuckets
{
public:
  /// @p count must outlive the buckets; levels outside [@p lowest, @p k] hold no voxel.
  CountBuckets(const std::vector<std::uint8_t>& count, int lowest, int k);

  /// The voxels (ascending) whose count is @p level; none below the lowest level.
  const std::vector<std::size_t>& at(int level);

private:
  const std::vector<std::uint8_t>& count_;
  int lowest_;
  int k_;
  std::vector<std::vector<std::size_t>> buckets_;
  std::vector<char> built_;  ///< by level: bucketed
  const std::vector<std::size_t> none_;
};

/**
 * @brief The conservative count field (an upper bound of the readings any pose of a voxel
 *        explains) tightened by the box test (BoxConsensusTest) where the seeds come from: when
 *        a level is asked for, the voxels of its regional maxima are screened (screenVoxels()),
 *        those whose box (or a block holding them) cannot explain that many readings lowered by
 *        one (the field stays an upper bound; they join the plateaus of the level below, where
 *        they are screened again), and the regional maxima of what is left returned. The
 *        count's own maxima are mostly places no pose explains their level (over 99 % where
 *        obstacles corrupt a third of the readings), each of which would cost a seed's
 *        verification. Levels must be asked for from the highest down, each once.
 */
class ScreenedCount
{
public:
  /// @p spec and @p count (the conservative field, copied) must outlive this.
  ScreenedCount(const GridSpec& spec, const std::vector<std::uint8_t>& count, int lowest, int k);

  /// Screens the voxels of the regional maxima at @p level (box test at @p screen's tolerance:
  /// the larger of the count's tau and the verification's agreement eps, so a voxel lowered
  /// holds no pose any verification would count at the level) and returns the regional maxima
  /// (regionalMaxima()) of the screened field at @p level.
  std::vector<VoxelCluster> maximaAt(int level, const BoxScreen& screen);

  /// The screened field: the conservative one with the voxels screened out lowered.
  const std::vector<std::uint8_t>& values() const
  {
    return count_;
  }

private:
  /// The voxels whose screened count is @p level (ascending), 1 <= @p level <= k.
  std::vector<std::size_t> voxelsAt(int level);

  const GridSpec& spec_;
  std::vector<std::uint8_t> count_;                ///< the screened field (copy of the conservative one)
  CountBuckets buckets_;                           ///< of the conservative field (unscreened)
  std::vector<std::vector<std::size_t>> lowered_;  ///< by level: voxels lowered to it
  VoxelSet members_;                               ///< the voxels being screened
};

}  // namespace core
}  // namespace fdml_localization
