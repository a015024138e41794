#include "fdml_localization/core/localization/voxel/box_screen.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/count_scan.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kTopBlock = BlockMaxima::kSide;

/// A block of voxels: [x0, x1) x [y0, y1) x [t0, t1) in cells.
struct Block
{
  int x0, x1, y0, y1, t0, t1;

  bool unit() const
  {
    return x1 - x0 == 1 && y1 - y0 == 1 && t1 - t0 == 1;
  }
};

/// Members: the voxels whose count lies in [lo, hi] (hi 255: reaches lo; hi == lo: equals it).
class CountMembers
{
public:
  CountMembers(const std::vector<std::uint8_t>& count, const GridSpec& spec, int lo, int hi)
    : count_(count), spec_(spec), lo_(lo), hi_(hi)
  {}

  bool has(int x, int y, int t) const
  {
    const int c = count_[spec_.index(x, y, t)];
    return c >= lo_ && c <= hi_;
  }

  /// Whether voxels [x0, x1) of row (y, t) hold a member; 8 at a time by a word test of their
  /// bytes (anyByteAtLeast() or anyByteEqual(), levels 1 to 128).
  bool anyInRow(int x0, int x1, int y, int t) const
  {
    const std::size_t row = spec_.index(0, y, t);
    if (x1 - x0 == 8 && lo_ >= 1 && lo_ <= 128 && (hi_ >= 255 || hi_ == lo_))
    {
      std::uint64_t word = 0;
      std::memcpy(&word, count_.data() + row + static_cast<std::size_t>(x0), 8);
      const unsigned lo = static_cast<unsigned>(lo_);
      return hi_ >= 255 ? anyByteAtLeast(word, lo) : anyByteEqual(word, lo);
    }
    for (int x = x0; x < x1; ++x)
    {
      const int c = count_[row + static_cast<std::size_t>(x)];
      if (c >= lo_ && c <= hi_)
      {
        return true;
      }
    }
    return false;
  }

private:
  const std::vector<std::uint8_t>& count_;
  const GridSpec& spec_;
  int lo_;
  int hi_;
};

/// Depth-first over a block's halves, down to voxels, of the members' verdicts.
template <typename Members>
class BlockSearch
{
public:
  /// @p lowered: where the members failing are set to needed - 1 (none: not recorded).
  BlockSearch(const GridSpec& spec, const Members& members, int needed, std::uint8_t* lowered, const BoxScreen& screen)
    : spec_(spec)
    , members_(members)
    , needed_(needed)
    , lowered_(lowered)
    , test_(screen.map, screen.readings, screen.tolerance)
  {}

  /// Appends the verdicts on @p b's members passing to @p out, and lowers those failing.
  void search(const Block& b, std::vector<VoxelVerdict>& out)
  {
    if (b.unit())
    {
      if (members_.has(b.x0, b.y0, b.t0))
      {
        const std::size_t v = spec_.index(b.x0, b.y0, b.t0);
        const int bound = test_.bound(voxelBox(spec_, v), needed_);
        if (bound >= needed_)
        {
          out.push_back(VoxelVerdict{ v, bound });
        }
        else if (lowered_)
        {
          // No pose of it explains the readings needed (below them the test stops early, so its
          // count bounds nothing): needed - 1 does.
          lowered_[v] = static_cast<std::uint8_t>(needed_ - 1);
        }
      }
      return;
    }
    if (!anyMember(b))
    {
      return;
    }
    if (!test_.reaches(blockBox(b), needed_))
    {
      failAll(b);
      return;
    }
    const int xm = (b.x0 + b.x1 + 1) / 2;
    const int ym = (b.y0 + b.y1 + 1) / 2;
    const int tm = (b.t0 + b.t1 + 1) / 2;
    for (const auto& t : { std::make_pair(b.t0, tm), std::make_pair(tm, b.t1) })
    {
      for (const auto& y : { std::make_pair(b.y0, ym), std::make_pair(ym, b.y1) })
      {
        for (const auto& x : { std::make_pair(b.x0, xm), std::make_pair(xm, b.x1) })
        {
          if (x.first < x.second && y.first < y.second && t.first < t.second)
          {
            search(Block{ x.first, x.second, y.first, y.second, t.first, t.second }, out);
          }
        }
      }
    }
  }

private:
  bool anyMember(const Block& b) const
  {
    for (int t = b.t0; t < b.t1; ++t)
    {
      for (int y = b.y0; y < b.y1; ++y)
      {
        if (members_.anyInRow(b.x0, b.x1, y, t))
        {
          return true;
        }
      }
    }
    return false;
  }

  /// Every member of @p b fails.
  void failAll(const Block& b) const
  {
    for (int t = b.t0; t < b.t1 && lowered_; ++t)
    {
      for (int y = b.y0; y < b.y1; ++y)
      {
        for (int x = b.x0; x < b.x1; ++x)
        {
          if (members_.has(x, y, t))
          {
            lowered_[spec_.index(x, y, t)] = static_cast<std::uint8_t>(needed_ - 1);
          }
        }
      }
    }
  }

  PoseBox blockBox(const Block& b) const
  {
    PoseBox box;
    box.x0 = spec_.origin_x + b.x0 * spec_.cell;
    box.x1 = spec_.origin_x + b.x1 * spec_.cell;
    box.y0 = spec_.origin_y + b.y0 * spec_.cell;
    box.y1 = spec_.origin_y + b.y1 * spec_.cell;
    box.t0 = -kPi + b.t0 * spec_.thetaStep();
    box.t1 = -kPi + b.t1 * spec_.thetaStep();
    return box;
  }

  const GridSpec& spec_;
  const Members& members_;
  int needed_;
  std::uint8_t* lowered_;
  BoxConsensusTest test_;
};

Block topBlockOf(const GridSpec& spec, int ix, int iy, int it)
{
  const int x = ix - ix % kTopBlock;
  const int y = iy - iy % kTopBlock;
  const int t = it - it % kTopBlock;
  return Block{ x, std::min(x + kTopBlock, spec.nx), y, std::min(y + kTopBlock, spec.ny),
                t, std::min(t + kTopBlock, spec.nt) };
}

/// The top blocks @p blocks reaching @p level.
std::vector<Block> topBlocks(const GridSpec& spec, const BlockMaxima& blocks, int level)
{
  std::vector<Block> out;
  const std::size_t bx = static_cast<std::size_t>(blocks.blocksX());
  const std::size_t by = static_cast<std::size_t>(blocks.blocksY());
  for (std::size_t b : blocks.reaching(level))
  {
    const int x = static_cast<int>(b % bx) * kTopBlock;
    const int y = static_cast<int>((b / bx) % by) * kTopBlock;
    const int t = static_cast<int>(b / (bx * by)) * kTopBlock;
    out.push_back(topBlockOf(spec, x, y, t));
  }
  return out;
}

/// The verdicts (ascending voxel) on @p members passing, block by block; those failing are set to
/// needed - 1 in @p lowered (if any). Threads take distinct top blocks, and a block's search reads
/// and writes only its own voxels (the word tests of a row read a top block's own 8 voxels).
template <typename Members>
std::vector<VoxelVerdict> screenMembers(const GridSpec& spec, const std::vector<Block>& blocks, const Members& members,
                                        int needed, std::uint8_t* lowered, const BoxScreen& screen)
{
  std::vector<std::vector<VoxelVerdict>> found(blocks.size());
#pragma omp parallel num_threads(screen.threads) if (blocks.size() >= 16)
  {
    BlockSearch<Members> search(spec, members, needed, lowered, screen);
#pragma omp for schedule(dynamic, 4)
    for (long b = 0; b < static_cast<long>(blocks.size()); ++b)
    {
      search.search(blocks[b], found[b]);
    }
  }
  std::vector<VoxelVerdict> verdicts;
  for (const auto& f : found)
  {
    verdicts.insert(verdicts.end(), f.begin(), f.end());
  }
  std::sort(verdicts.begin(), verdicts.end(),
            [](const VoxelVerdict& a, const VoxelVerdict& b) { return a.voxel < b.voxel; });
  return verdicts;
}
}  // namespace

BlockMaxima::BlockMaxima(const GridSpec& spec, const std::vector<std::uint8_t>& count)
  : bx_((spec.nx + kSide - 1) / kSide)
  , by_((spec.ny + kSide - 1) / kSide)
  , bt_((spec.nt + kSide - 1) / kSide)
  , max_(static_cast<std::size_t>(bx_) * by_ * bt_, 0)
{
  // Per block row: the rows' element-wise maximum (vectorised), then each block's 8 columns.
  std::vector<std::uint8_t> columns(static_cast<std::size_t>(bx_) * kSide, 0);
  for (int bt = 0; bt < bt_; ++bt)
  {
    for (int by = 0; by < by_; ++by)
    {
      std::fill(columns.begin(), columns.end(), 0);
      for (int t = bt * kSide; t < std::min(spec.nt, (bt + 1) * kSide); ++t)
      {
        for (int y = by * kSide; y < std::min(spec.ny, (by + 1) * kSide); ++y)
        {
          const std::uint8_t* row = count.data() + spec.index(0, y, t);
          for (int x = 0; x < spec.nx; ++x)
          {
            columns[x] = std::max(columns[x], row[x]);
          }
        }
      }
      std::uint8_t* out = max_.data() + (static_cast<std::size_t>(bt) * by_ + by) * bx_;
      for (int b = 0; b < bx_; ++b)
      {
        out[b] = *std::max_element(columns.begin() + b * kSide, columns.begin() + (b + 1) * kSide);
      }
    }
  }
}

std::vector<std::size_t> BlockMaxima::reaching(int level) const
{
  std::vector<std::size_t> blocks;
  for (std::size_t b = 0; b < max_.size(); ++b)
  {
    if (max_[b] >= level)
    {
      blocks.push_back(b);
    }
  }
  return blocks;
}

std::vector<VoxelVerdict> screenLevel(const GridSpec& spec, std::vector<std::uint8_t>& count, int level,
                                      const BlockMaxima& blocks, const BoxScreen& screen)
{
  if (level < 1 || level > 255)
  {
    return {};
  }
  return screenMembers(spec, topBlocks(spec, blocks, level), CountMembers(count, spec, level, level), level,
                       count.data(), screen);
}

std::vector<LeafBox> reachingLeaves(const GridSpec& spec, const std::vector<std::uint8_t>& count, int target,
                                    const BlockMaxima& blocks, const BoxScreen& screen)
{
  const int needed = std::clamp(target, 0, 255);
  std::vector<LeafBox> leaves;
  for (const VoxelVerdict& v : screenMembers(spec, topBlocks(spec, blocks, needed),
                                             CountMembers(count, spec, needed, 255), needed, nullptr, screen))
  {
    leaves.push_back(voxelLeaf(spec, v.voxel, std::min<int>(count[v.voxel], v.bound)));
  }
  return leaves;
}

}  // namespace core
}  // namespace fdml_localization
