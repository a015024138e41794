/**
 * @file leaf_clustering.h
 * @brief Clusters of the adaptive search's surviving leaves: connected components and regional
 *        maxima on the leaf lattice (26 neighbours, periodic in theta), each giving seeds.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A cluster of surviving leaves: its peak-count plateau gives one seed.
struct LeafCluster
{
  Pose2 centroid;                  ///< mean x, y [m], circular mean theta [rad] of the plateau leaves
  std::size_t representative = 0;  ///< index (into the leaves) of the plateau leaf nearest the centroid
  std::size_t size = 0;            ///< leaves in the whole connected component
  int peak_count = 0;
  std::vector<std::size_t> members;  ///< plateau leaves (leafMaxima only), ascending
};

/**
 * @brief Connected components (26 neighbours on the leaf lattice, periodic in theta with
 *        @p theta_cells cells) of the leaves with count >= @p level; each component yields one
 *        cluster per connected plateau of its peak count (peaks are never averaged together).
 */
std::vector<LeafCluster> clusterLeaves(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells);

/**
 * @brief Regional maxima at exactly @p level: connected plateaus (26 neighbours, periodic theta)
 *        of the leaves with count == level that touch no leaf with a higher count; largest first.
 */
std::vector<LeafCluster> leafMaxima(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells);

/// The heading cells of @p cell_theta [rad] around the circle (at least 1): the theta_cells of
/// the functions below for leaves of that size.
std::int64_t thetaCells(double cell_theta);

/**
 * @brief The connected components (26 neighbours, periodic theta) of the leaves with count >=
 *        @p level: one label per leaf, -1 for the leaves below @p level.
 * @param components receives the number of components (labels 0 .. components - 1)
 */
std::vector<int> leafComponents(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells,
                                int& components);

/**
 * @brief The leaves of a component (@p labels >= 0, leafComponents()) worth searching for a
 *        place explaining @p target readings: every one whose count exceeds it (it may beat
 *        the best place found), the highest counts first, up to @p limit (a count whose
 *        leaves overflow it spread evenly over them); then those at
 *        @p target, every one or, where there are more than @p limit, every n-th (at least
 *        @p limit, fewer than twice as many). Indices into @p leaves.
 */
std::vector<std::size_t> leavesToSearch(const std::vector<LeafBox>& leaves, const std::vector<int>& labels, int target,
                                        std::size_t limit);

/// The box of poses of voxel @p v of @p spec: its cell [m] by its heading step [rad] (from -pi).
PoseBox voxelBox(const GridSpec& spec, std::size_t v);

/**
 * @brief Voxel @p v of @p spec as a leaf holding @p count readings (voxelBox(), the voxel's
 *        indices as the leaf's cell): the voxel engine's cells searched as the adaptive engine's
 *        leaves are (region_fill.h). Heading cells: spec.nt.
 */
LeafBox voxelLeaf(const GridSpec& spec, std::size_t v, int count);

}  // namespace core
}  // namespace fdml_localization
