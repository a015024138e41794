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
/// The voxels of a count field by count, each level bucketed when first asked for: the low levels
/// hold most voxels and are rarely reached. Only the rows (of @p row_length voxels) whose largest
/// count reaches a level are scanned for it.
class CountBuckets
{
public:
  /// @p count must outlive the buckets; levels outside [@p lowest, @p k] hold no voxel.
  CountBuckets(const std::vector<std::uint8_t>& count, int row_length, int lowest, int k);

  /// The voxels (ascending) whose count is @p level; none below the lowest level.
  const std::vector<std::size_t>& at(int level);

private:
  const std::vector<std::uint8_t>& count_;
  std::size_t row_length_;
  int lowest_;
  int k_;
  std::vector<std::uint8_t> row_max_;  ///< by row: its largest count (found on the first call)
  std::vector<std::vector<std::size_t>> buckets_;
  std::vector<char> built_;  ///< by level: bucketed
  const std::vector<std::size_t> none_;
};

/**
 * @brief The conservative count field (an upper bound of the readings any pose of a voxel
 *        explains) tightened by the box test (BoxConsensusTest) where the seeds come from: when
 *        a level is asked for, the voxels of its regional maxima are screened (screenLevel()),
 *        those whose box (or a block holding them) cannot explain that many readings lowered by
 *        one (the field stays an upper bound; they are screened again at the level below), and
 *        the regional maxima of what is left returned. The count's own maxima are mostly places
 *        no pose explains their level (over 99 % where obstacles corrupt a third of the
 *        readings), each of which would cost a seed's verification. Levels are asked for from
 *        the highest down; one below a level skipped costs a scan of the field.
 */
class ScreenedCount
{
public:
  /// @p spec and @p blocks (BlockMaxima of @p count) must outlive this; @p count (the
  /// conservative field) is copied.
  ScreenedCount(const GridSpec& spec, const std::vector<std::uint8_t>& count, const BlockMaxima& blocks);

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
  const GridSpec& spec_;
  std::vector<std::uint8_t> count_;  ///< the screened field (copy of the conservative one)
  const BlockMaxima& blocks_;        ///< of the conservative field
  /// Whether some voxel lies above the next level (none: no plateau there is lifted).
  bool any_above_ = false;
  int next_level_ = -1;  ///< the level maximaAt() expects next (any_above_ is for it)
};

}  // namespace core
}  // namespace fdml_localization
