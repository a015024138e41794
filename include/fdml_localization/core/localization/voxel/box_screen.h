/**
 * @file box_screen.h
 * @brief The box test (BoxConsensusTest) over the voxel engine's grid: which voxels reaching a
 *        consensus in the count field may reach it by the box test, a tighter bound. Blocks of
 *        voxels are tested first, from 8 x 8 x 8 down, halving, so a block whose box cannot
 *        explain the consensus rules out all its voxels with one test: over 99 % of the voxels a
 *        count field lets reach a low consensus fail it.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// The box test's inputs (the map and readings must outlive it).
struct BoxScreen
{
  const MapRayCaster& map;
  const std::vector<Reading>& readings;
  double tolerance = 0.0;  ///< the box test's range tolerance [m]
  int threads = 1;
};

/**
 * @brief The largest count in each top block (8 x 8 x 8 voxels, the coarsest a screen tests) of
 *        a count field, so that a screen visits only the blocks that may hold a voxel of its
 *        level. Still a bound of the field when it is lowered afterwards (ScreenedCount).
 */
class BlockMaxima
{
public:
  /// Voxels along each side of a top block.
  static constexpr int kSide = 8;

  BlockMaxima(const GridSpec& spec, const std::vector<std::uint8_t>& count);

  /// The top blocks (index (bt * by + byi) * bx + bxi, ascending) whose largest count is at
  /// least @p level.
  std::vector<std::size_t> reaching(int level) const;

  int blocksX() const
  {
    return bx_;
  }
  int blocksY() const
  {
    return by_;
  }

private:
  int bx_ = 0;
  int by_ = 0;
  int bt_ = 0;
  std::vector<std::uint8_t> max_;  ///< by top block
};

/// A voxel passing the box test, with the test's bound (BoxConsensusTest::bound(): a sound bound
/// of the readings a pose of it explains).
struct VoxelVerdict
{
  std::size_t voxel = 0;
  int bound = -1;
};

/**
 * @brief Screens every voxel v with @p count[v] == @p level (1 to 255): whether its box may
 *        explain @p level readings (@p blocks: BlockMaxima of @p count or of a field above it).
 *        A voxel fails with a block holding it whose box cannot explain them (no pose in it can:
 *        the box test is sound, though not monotone, so a voxel's own box can pass where a
 *        block's failed), or by its own box; it is then lowered to level - 1 in @p count.
 * @return the voxels passing (ascending voxel)
 */
std::vector<VoxelVerdict> screenLevel(const GridSpec& spec, std::vector<std::uint8_t>& count, int level,
                                      const BlockMaxima& blocks, const BoxScreen& screen);

/**
 * @brief The voxels v of @p spec with @p count[v] >= @p target that pass the box test at
 *        @p target readings as screenLevel() tests them, as leaves (voxelLeaf(), ascending v)
 *        counting min(count[v], the box test's bound).
 */
std::vector<LeafBox> reachingLeaves(const GridSpec& spec, const std::vector<std::uint8_t>& count, int target,
                                    const BlockMaxima& blocks, const BoxScreen& screen);

}  // namespace core
}  // namespace fdml_localization
