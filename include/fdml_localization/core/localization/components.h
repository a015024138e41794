/**
 * @file components.h
 * @brief Connected sets of voxels in a count field: 26-neighbour connectivity, periodic in
 *        theta, found iteratively (no recursion), with centroids averaged on the circle in theta.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// One connected set of voxels.
struct VoxelCluster
{
  std::vector<std::size_t> voxels;  ///< linear voxel indices
  Pose2 centroid;                   ///< mean x, y [m]; circular mean theta [rad]
  int peak_count = 0;               ///< highest count inside the cluster
  std::size_t representative = 0;   ///< the voxel of the cluster nearest its centroid
};

/**
 * @brief Calls fn(neighbour_index) for each of the (up to) 26 neighbours of voxel
 *        (ix, iy, it): x and y are clipped at the grid's edge, theta wraps around.
 */
template <typename Fn>
void forEachNeighbour(const GridSpec& spec, int ix, int iy, int it, Fn&& fn)
{
  for (int dt = -1; dt <= 1; ++dt)
  {
    int t = it + dt;
    t = t < 0 ? t + spec.nt : (t >= spec.nt ? t - spec.nt : t);
    for (int dy = -1; dy <= 1; ++dy)
    {
      const int y = iy + dy;
      if (y < 0 || y >= spec.ny)
      {
        continue;
      }
      for (int dx = -1; dx <= 1; ++dx)
      {
        const int x = ix + dx;
        if (x < 0 || x >= spec.nx || (dx == 0 && dy == 0 && dt == 0))
        {
          continue;
        }
        fn(spec.index(x, y, t));
      }
    }
  }
}

/// Mean position and circular-mean angle of voxel centres; fills centroid and representative.
void computeCentroid(const GridSpec& spec, VoxelCluster& cluster);

/**
 * @brief The connected components of {v : count[v] >= level}, largest peak first (then
 *        largest size). @p count holds one value per voxel (GridSpec::index order).
 */
std::vector<VoxelCluster> connectedComponents(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level);

/**
 * @brief The size of the connected component of {v : count[v] >= level} holding @p seed
 *        (0 when count[seed] < level).
 */
std::size_t componentSize(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level, std::size_t seed);

/// componentSize() for several seeds at once; each component is flooded once, 64 voxels along x
/// at a time (LevelMasks).
std::vector<std::size_t> componentSizes(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                        const std::vector<std::size_t>& seeds);

/**
 * @brief Lifts to @p level + 1 (0 <= level <= 254) the voxels at exactly @p level outside its
 *        regional maxima (regionalMaxima()): those connected, through voxels at the level, to a
 *        voxel above it. Flooded 64 voxels along x at a time (LevelMasks).
 * @return the voxels lifted (ascending)
 */
std::vector<std::size_t> liftNonMaximalPlateaus(const GridSpec& spec, std::vector<std::uint8_t>& count, int level);

/**
 * @brief The regional maxima of the count field at exactly @p level: connected plateaus of
 *        voxels with count == level none of whose neighbours has a higher count. Every count
 *        peak of a component becomes its own cluster (peaks are never merged into one centroid).
 * @param candidates every voxel with count == level (any order)
 */
std::vector<VoxelCluster> regionalMaxima(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                         const std::vector<std::size_t>& candidates);

}  // namespace core
}  // namespace fdml_localization
