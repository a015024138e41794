#include "fdml_localization/core/localization/hypothesis_seeds.h"

#include <omp.h>

#include <algorithm>

namespace fdml_localization
{
namespace core
{
namespace
{
/// True when every set holding voxel a also holds voxel b.
bool membershipWithin(const std::vector<VoxelSet>& sets, int ax, int ay, int at, int bx, int by, int bt)
{
  for (const VoxelSet& set : sets)
  {
    if (set.test(ax, ay, at) && !set.test(bx, by, bt))
    {
      return false;
    }
  }
  return true;
}
/// Per voxel of @p voxels: 1 unless a neighbour with a higher count holds all of its readings.
std::vector<char> undominated(const GridSpec& spec, const std::vector<VoxelSet>& sets,
                              const std::vector<std::uint8_t>& count, const std::vector<std::size_t>& voxels,
                              int threads)
{
  std::vector<char> kept(voxels.size(), 0);
#pragma omp parallel for schedule(dynamic, 256) num_threads(threads)
  for (long c = 0; c < static_cast<long>(voxels.size()); ++c)
  {
    const std::size_t v = voxels[c];
    int ix = 0, iy = 0, it = 0;
    spec.unindex(v, ix, iy, it);
    bool dominated = false;
    forEachNeighbour(spec, ix, iy, it, [&](std::size_t u) {
      if (dominated || count[u] <= count[v])
      {
        return;
      }
      int ux = 0, uy = 0, ut = 0;
      spec.unindex(u, ux, uy, ut);
      dominated = membershipWithin(sets, ix, iy, it, ux, uy, ut);
    });
    kept[c] = dominated ? 0 : 1;
  }
  return kept;
}

/// The plateau of seed voxels connected to @p v with the same membership, marked visited.
HypothesisSeed growPlateau(const GridSpec& spec, const std::vector<VoxelSet>& sets, const VoxelSet& seed_voxels,
                           std::size_t v, int level, VoxelSet& visited)
{
  int ix = 0, iy = 0, it = 0;
  spec.unindex(v, ix, iy, it);
  HypothesisSeed seed;
  seed.plateau.peak_count = level;
  seed.hypothesis.resize(sets.size());
  for (std::size_t i = 0; i < sets.size(); ++i)
  {
    seed.hypothesis[i] = sets[i].test(ix, iy, it);
  }
  visited.set(ix, iy, it);
  std::vector<std::size_t> stack(1, v);
  while (!stack.empty())
  {
    const std::size_t w = stack.back();
    stack.pop_back();
    seed.plateau.voxels.push_back(w);
    int wx = 0, wy = 0, wt = 0;
    spec.unindex(w, wx, wy, wt);
    forEachNeighbour(spec, wx, wy, wt, [&](std::size_t u) {
      int ux = 0, uy = 0, ut = 0;
      spec.unindex(u, ux, uy, ut);
      if (!seed_voxels.test(ux, uy, ut) || visited.test(ux, uy, ut) || !membershipWithin(sets, ix, iy, it, ux, uy, ut))
      {
        return;
      }
      visited.set(ux, uy, ut);
      stack.push_back(u);
    });
  }
  std::sort(seed.plateau.voxels.begin(), seed.plateau.voxels.end());
  computeCentroid(spec, seed.plateau);
  return seed;
}
}  // namespace

std::vector<HypothesisSeed> maximalHypotheses(const GridSpec& spec, const std::vector<VoxelSet>& sets,
                                              const std::vector<std::uint8_t>& count, int level,
                                              const std::vector<std::size_t>& voxels, int threads)
{
  // A voxel is dominated when a neighbour with a higher count holds all of its readings.
  const std::vector<char> kept = undominated(spec, sets, count, voxels, threads);
  // Plateaus: kept voxels connected through kept neighbours with the same membership.
  VoxelSet seed_voxels(spec);
  for (std::size_t c = 0; c < voxels.size(); ++c)
  {
    if (kept[c])
    {
      int ix = 0, iy = 0, it = 0;
      spec.unindex(voxels[c], ix, iy, it);
      seed_voxels.set(ix, iy, it);
    }
  }
  VoxelSet visited(spec);
  std::vector<HypothesisSeed> seeds;
  for (std::size_t c = 0; c < voxels.size(); ++c)
  {
    int ix = 0, iy = 0, it = 0;
    spec.unindex(voxels[c], ix, iy, it);
    if (kept[c] && !visited.test(ix, iy, it))
    {
      seeds.push_back(growPlateau(spec, sets, seed_voxels, voxels[c], level, visited));
    }
  }
  return seeds;
}

}  // namespace core
}  // namespace fdml_localization
