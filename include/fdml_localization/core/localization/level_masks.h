/**
 * @file level_runs.h
 * @brief The voxels of a count field reaching a level as runs along x, row by row, so that the
 *        sizes of its connected components (26 neighbours, periodic in theta, as components.h)
 *        are found run by run instead of voxel by voxel.
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
/// {v : count[v] >= level} of a count field (GridSpec::index order), a row's runs found when the
/// row is first reached.
class LevelRuns
{
public:
  /// @p spec and @p count must outlive this.
  LevelRuns(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level);

  /// For each of @p voxels, the number of voxels of its connected component (0 for a voxel below
  /// the level or outside the grid); each component is walked once.
  std::vector<std::size_t> componentSizes(const std::vector<std::size_t>& voxels);

private:
  /// Voxels [x0, x1) of a row.
  struct Run
  {
    int x0;
    int x1;
  };

  /// The runs of row @p row ((it * ny + iy)), found on first use.
  const std::vector<Run>& runsOf(std::size_t row);
  /// The run of row @p row holding @p x, or -1.
  long runAt(std::size_t row, int x);
  /// The voxels of the component holding run @p run of row @p row, its runs labelled @p label.
  std::size_t walk(std::size_t row, std::size_t run, int label);

  const GridSpec& spec_;
  const std::vector<std::uint8_t>& count_;
  int level_;
  std::vector<std::vector<Run>> runs_;    ///< by row
  std::vector<char> built_;               ///< by row: runs_ found
  std::vector<std::vector<int>> labels_;  ///< by row and run: component label, -1 none yet
};

}  // namespace core
}  // namespace fdml_localization
