#include "fdml_localization/core/localization/voxel/count_buckets.h"

#include "fdml_localization/core/localization/count_scan.h"

#include <algorithm>

namespace fdml_localization
{
namespace core
{
CountBuckets::CountBuckets(const std::vector<std::uint8_t>& count, int row_length, int lowest, int k)
  : count_(count)
  , row_length_(static_cast<std::size_t>(std::max(row_length, 1)))
  , lowest_(lowest)
  , k_(k)
  , buckets_(static_cast<std::size_t>(std::max(k, 0)) + 1)
  , built_(static_cast<std::size_t>(std::max(k, 0)) + 1, 0)
{}

const std::vector<std::size_t>& CountBuckets::at(int level)
{
  if (level < std::max(lowest_, 1) || level > std::min(k_, 255))
  {
    return none_;
  }
  if (!built_[level])
  {
    built_[level] = 1;
    const std::size_t rows = count_.size() / row_length_;
    if (row_max_.empty())
    {
      row_max_.resize(rows + 1);  // the last entry: a partial row, if any
      for (std::size_t r = 0; r * row_length_ < count_.size(); ++r)
      {
        const auto first = count_.begin() + static_cast<std::ptrdiff_t>(r * row_length_);
        const auto last = count_.begin() + static_cast<std::ptrdiff_t>(std::min(count_.size(), (r + 1) * row_length_));
        row_max_[r] = *std::max_element(first, last);
      }
    }
    for (std::size_t r = 0; r < row_max_.size(); ++r)
    {
      if (row_max_[r] >= level)
      {
        appendVoxelsAt(count_, r * row_length_, (r + 1) * row_length_, level, buckets_[level]);
      }
    }
  }
  return buckets_[level];
}

ScreenedCount::ScreenedCount(const GridSpec& spec, const std::vector<std::uint8_t>& count, const BlockMaxima& blocks)
  : spec_(spec), count_(count), blocks_(blocks)
{}

std::vector<VoxelCluster> ScreenedCount::maximaAt(int level, const BoxScreen& screen)
{
  if (level < 1 || level > 255)
  {
    return {};
  }
  if (level != next_level_)
  {
    // The first level asked for (or one below a level skipped).
    any_above_ = std::any_of(count_.begin(), count_.end(), [level](std::uint8_t c) { return c > level; });
  }
  next_level_ = level - 1;
  // The plateaus touching a voxel above the level are no maxima: lifted above it while the level
  // is screened (so they are not), then put back. (None at level 255: no count is above it.)
  const std::vector<std::size_t> lower =
      any_above_ ? liftNonMaximalPlateaus(spec_, count_, level) : std::vector<std::size_t>();
  // The voxels failing are lowered to level - 1: no pose of them explains `level` readings.
  std::vector<std::size_t> kept;
  for (const VoxelVerdict& v : screenLevel(spec_, count_, level, blocks_, screen))
  {
    kept.push_back(v.voxel);
  }
  for (std::size_t v : lower)
  {
    count_[v] = static_cast<std::uint8_t>(level);
  }
  // Those left at the level are above the next one.
  any_above_ = any_above_ || !kept.empty();
  return regionalMaxima(spec_, count_, level, kept);
}

}  // namespace core
}  // namespace fdml_localization
