/**
 * @file hypothesis_seeds.h
 * @brief Seeds of the robust search: the voxels whose set of explained readings no neighbouring
 *        voxel strictly extends ("maximal hypotheses").
 *
 * Where k' of k readings hit the static map, the voxels near the truth lie in those k'
 * preimages and in whichever obstacle hits' preimages happen to pass by. A regional maximum of
 * the count field can sit a voxel away from the truth, on the surface of an obstacle hit, with
 * a different set of readings; the truth's own set is then never tried. A voxel whose set no
 * neighbour extends is a locally maximal consistent set of readings, whatever its count, so
 * each such set is tried once, from the plateau of voxels that share it.
 */
#pragma once

#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A plateau of 26-connected voxels that lie in exactly the same preimages.
struct HypothesisSeed
{
  VoxelCluster plateau;          ///< voxels, centroid, representative; peak_count = readings explained
  std::vector<bool> hypothesis;  ///< per reading: its preimage holds the plateau
};

/**
 * @brief The maximal hypotheses among the voxels in exactly @p level of @p sets: voxel v is
 *        kept unless a neighbour lies in every set that holds v and in at least one more.
 *        Kept voxels with the same membership are grouped into connected plateaus.
 * @param count count[v] = number of @p sets holding voxel v
 * @param voxels every voxel with count == level, in increasing order
 * @param threads OpenMP threads for the dominance test
 * @return one seed per plateau, in voxel order (deterministic)
 */
std::vector<HypothesisSeed> maximalHypotheses(const GridSpec& spec, const std::vector<VoxelSet>& sets,
                                              const std::vector<std::uint8_t>& count, int level,
                                              const std::vector<std::size_t>& voxels, int threads);

}  // namespace core
}  // namespace fdml_localization
