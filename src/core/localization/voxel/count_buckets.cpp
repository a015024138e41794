#include "fdml_localization/core/localization/voxel/count_buckets.h"

#include <algorithm>
#include <iterator>

namespace fdml_localization
{
namespace core
{
CountBuckets::CountBuckets(const std::vector<std::uint8_t>& count, int lowest, int k)
  : count_(count)
  , lowest_(lowest)
  , k_(k)
  , buckets_(static_cast<std::size_t>(std::max(k, 0)) + 1)
  , built_(static_cast<std::size_t>(std::max(k, 0)) + 1, 0)
{}

const std::vector<std::size_t>& CountBuckets::at(int level)
{
  if (level < lowest_ || level > k_)
  {
    return none_;
  }
  if (!built_[level])
  {
    buckets_[level] = std::move(voxelsByCount(count_, level, level)[level]);
    built_[level] = 1;
  }
  return buckets_[level];
}

ScreenedCount::ScreenedCount(const GridSpec& spec, const std::vector<std::uint8_t>& count, int lowest, int k)
  : spec_(spec)
  , count_(count)
  , buckets_(count, lowest, k)
  , lowered_(static_cast<std::size_t>(std::max(k, 0)) + 1)
  , members_(spec)
{}

std::vector<std::size_t> ScreenedCount::voxelsAt(int level)
{
  const std::vector<std::size_t>& original = buckets_.at(level);
  std::vector<std::size_t>& lowered = lowered_[level];
  if (lowered.empty())
  {
    return original;
  }
  std::sort(lowered.begin(), lowered.end());
  std::vector<std::size_t> voxels;
  voxels.reserve(original.size() + lowered.size());
  std::merge(original.begin(), original.end(), lowered.begin(), lowered.end(), std::back_inserter(voxels));
  lowered.clear();
  lowered.shrink_to_fit();
  return voxels;
}

std::vector<VoxelCluster> ScreenedCount::maximaAt(int level, const BoxScreen& screen)
{
  if (level < 1 || level >= static_cast<int>(lowered_.size()))
  {
    return {};
  }
  members_.clear();
  std::vector<std::size_t> voxels;
  for (const VoxelCluster& plateau : regionalPlateaus(spec_, count_, level, voxelsAt(level)))
  {
    for (std::size_t v : plateau.voxels)
    {
      int ix = 0, iy = 0, it = 0;
      spec_.unindex(v, ix, iy, it);
      members_.set(ix, iy, it);
      voxels.push_back(v);
    }
  }
  std::vector<std::size_t> kept;
  for (const VoxelVerdict& v : screenVoxels(spec_, members_, voxels, level, screen))
  {
    if (v.bound >= level)
    {
      kept.push_back(v.voxel);
      continue;
    }
    // No pose of the voxel explains `level` readings: at most level - 1.
    count_[v.voxel] = static_cast<std::uint8_t>(level - 1);
    lowered_[level - 1].push_back(v.voxel);
  }
  // The voxels kept are those of the maxima (their neighbours at the level are theirs too).
  return regionalMaxima(spec_, count_, level, kept);
}

}  // namespace core
}  // namespace fdml_localization
