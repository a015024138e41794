/**
 * @file level_masks.h
 * @brief The voxels of a count field reaching a level as bit masks along x, row by row, so that
 *        the sizes of its connected components (26 neighbours, periodic in theta, as
 *        components.h) are flooded 64 voxels at a time instead of voxel by voxel.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// {v : level <= count[v] <= top} of a count field (GridSpec::index order; top 255 by default:
/// the voxels reaching the level), a row's mask built when the row is first reached.
class LevelMasks
{
public:
  /// @p spec and @p count must outlive this; throws std::invalid_argument when @p count is not
  /// one value per voxel of @p spec.
  LevelMasks(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level, int top = 255);

  /// For each of @p voxels, the number of voxels of its connected component (0 for a voxel below
  /// the level or outside the grid); each component is flooded once.
  std::vector<std::size_t> componentSizes(const std::vector<std::size_t>& voxels);

  /**
   * @brief The number of connected components of the voxels reaching the level, each flooded
   *        once (those an earlier call flooded are counted too).
   * @param voxels voxels whose components are flooded first
   * @param holding set to the number of components holding one of @p voxels (of those not
   *        flooded before this call)
   */
  std::size_t componentCount(const std::vector<std::size_t>& voxels, std::size_t& holding);

  /**
   * @brief Floods the components holding a voxel of @p source (a mask of the same grid) or one
   *        of its neighbours (26, periodic in theta): every voxel of this mask connected to
   *        @p source.
   * @return the voxels this call adds to the flooded ones
   */
  std::size_t floodNeighboursOf(LevelMasks& source);

  /// The voxels of the components flooded so far (ascending).
  std::vector<std::size_t> floodedVoxels() const;

private:
  using Word = std::uint64_t;

  /// Row @p row's ((it * ny + iy)) mask of the voxels reaching the level, built on first use.
  const Word* levelOf(std::size_t row);
  /// Adds to the flood the voxels of row @p row's runs (along x) that hold a bit of @p seeds
  /// (words_ words); returns how many voxels that adds.
  std::size_t fill(std::size_t row, const Word* seeds);
  /// The voxels of the component holding row @p row's voxel @p x (reaching the level), flooded
  /// into reached_.
  std::size_t flood(std::size_t row, int x);
  /// Spreads the flood from the rows on its stack to their neighbour rows until none is left;
  /// returns the voxels added.
  std::size_t spread();
  /// Fills, in the rows around @p row (itself too when @p self), the voxels neighbouring those of
  /// @p from (a row's words_ words); returns the voxels added.
  std::size_t spreadFrom(const Word* from, std::size_t row, bool self);
  /// Calls @p fn(next) for the rows around @p row (periodic in theta), itself included when
  /// @p self.
  template <typename Fn>
  void forEachRowAround(std::size_t row, bool self, Fn&& fn) const;
  /// Floods the component of each of @p voxels reaching the level not flooded yet; @p sizes[k]
  /// (sized as @p voxels) set to the size of voxel k's component when this call floods it.
  /// Returns the number of components flooded.
  std::size_t floodEach(const std::vector<std::size_t>& voxels, std::vector<std::size_t>& sizes);

  const GridSpec& spec_;
  const std::vector<std::uint8_t>& count_;
  int level_;
  int top_;
  std::size_t words_;               ///< per row
  std::vector<Word> level_bits_;    ///< by row, words_ each: voxels reaching the level (once built_)
  std::vector<char> built_;         ///< by row
  std::vector<Word> reached_;       ///< by row: voxels of the components flooded so far
  std::vector<char> queued_;        ///< by row: on the flood's stack
  std::vector<std::size_t> stack_;  ///< rows whose new voxels are still to be spread
  std::vector<Word> runs_;          ///< fill()'s scratch row
  std::vector<Word> spread_;        ///< spreadFrom()'s scratch rows
  std::vector<Word> seeds_;
  std::size_t floods_ = 0;  ///< components flooded so far
};

}  // namespace core
}  // namespace fdml_localization
