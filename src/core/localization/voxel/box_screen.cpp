#include "fdml_localization/core/localization/voxel/box_screen.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/components.h"

#include <algorithm>
#include <cstring>
#include <utility>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Voxels along each side of the coarsest blocks tested.
constexpr int kTopBlock = 8;

/// A block of voxels: [x0, x1) x [y0, y1) x [t0, t1) in cells.
struct Block
{
  int x0, x1, y0, y1, t0, t1;

  bool unit() const
  {
    return x1 - x0 == 1 && y1 - y0 == 1 && t1 - t0 == 1;
  }
};

/// Members: the voxels whose count reaches a level.
class CountMembers
{
public:
  CountMembers(const std::vector<std::uint8_t>& count, const GridSpec& spec, int level)
    : count_(count), spec_(spec), level_(level)
  {}

  bool has(int x, int y, int t) const
  {
    return count_[spec_.index(x, y, t)] >= level_;
  }

  /// Whether voxels [x0, x1) of row (y, t) hold a member; 8 at a time by a word test of their
  /// bytes (anyByteAtLeast(), levels 1 to 128).
  bool anyInRow(int x0, int x1, int y, int t) const
  {
    const std::size_t row = spec_.index(0, y, t);
    if (x1 - x0 == 8 && level_ >= 1 && level_ <= 128)
    {
      std::uint64_t word = 0;
      std::memcpy(&word, count_.data() + row + static_cast<std::size_t>(x0), 8);
      return anyByteAtLeast(word, static_cast<unsigned>(level_));
    }
    for (int x = x0; x < x1; ++x)
    {
      if (count_[row + static_cast<std::size_t>(x)] >= level_)
      {
        return true;
      }
    }
    return false;
  }

private:
  const std::vector<std::uint8_t>& count_;
  const GridSpec& spec_;
  int level_;
};

/// Members: the voxels of a set.
class SetMembers
{
public:
  explicit SetMembers(const VoxelSet& set) : set_(set)
  {}

  bool has(int x, int y, int t) const
  {
    return set_.test(x, y, t);
  }

  bool anyInRow(int x0, int x1, int y, int t) const
  {
    const std::uint64_t* row = set_.row(y, t);
    for (int x = x0; x < x1;)
    {
      const int end = std::min(x1, (x & ~63) + 64);  // within one word
      const std::uint64_t bits = row[x >> 6] >> (x & 63);
      const int n = end - x;
      if ((n == 64 ? bits : bits & ((std::uint64_t(1) << n) - 1)) != 0)
      {
        return true;
      }
      x = end;
    }
    return false;
  }

private:
  const VoxelSet& set_;
};

/// Depth-first over a block's halves, down to voxels, of the members' verdicts.
template <typename Members>
class BlockSearch
{
public:
  BlockSearch(const GridSpec& spec, const Members& members, int needed, bool with_failed, const BoxScreen& screen)
    : spec_(spec)
    , members_(members)
    , needed_(needed)
    , with_failed_(with_failed)
    , test_(screen.map, screen.readings, screen.tolerance)
  {}

  /// Appends the verdicts on @p b's members to @p out (failed ones only if asked for).
  void search(const Block& b, std::vector<VoxelVerdict>& out)
  {
    if (b.unit())
    {
      if (members_.has(b.x0, b.y0, b.t0))
      {
        const std::size_t v = spec_.index(b.x0, b.y0, b.t0);
        const int bound = test_.bound(voxelBox(spec_, v), needed_);
        if (bound >= needed_ || with_failed_)
        {
          // Below the readings needed the test stops early: its count bounds nothing.
          out.push_back(VoxelVerdict{ v, bound >= needed_ ? bound : needed_ - 1 });
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
      failAll(b, out);
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

  /// Every member of @p b fails, into @p out if failed ones are asked for.
  void failAll(const Block& b, std::vector<VoxelVerdict>& out) const
  {
    for (int t = b.t0; t < b.t1 && with_failed_; ++t)
    {
      for (int y = b.y0; y < b.y1; ++y)
      {
        for (int x = b.x0; x < b.x1; ++x)
        {
          if (members_.has(x, y, t))
          {
            out.push_back(VoxelVerdict{ spec_.index(x, y, t), needed_ - 1 });
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
  bool with_failed_;
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

/// The top blocks holding @p voxels, in index order of their first voxel.
std::vector<Block> topBlocksOf(const GridSpec& spec, const std::vector<std::size_t>& voxels)
{
  std::vector<std::size_t> starts;
  for (std::size_t v : voxels)
  {
    int ix = 0, iy = 0, it = 0;
    spec.unindex(v, ix, iy, it);
    const Block b = topBlockOf(spec, ix, iy, it);
    starts.push_back(spec.index(b.x0, b.y0, b.t0));
  }
  std::sort(starts.begin(), starts.end());
  starts.erase(std::unique(starts.begin(), starts.end()), starts.end());
  std::vector<Block> blocks;
  for (std::size_t s : starts)
  {
    int ix = 0, iy = 0, it = 0;
    spec.unindex(s, ix, iy, it);
    blocks.push_back(topBlockOf(spec, ix, iy, it));
  }
  return blocks;
}

std::vector<Block> topBlocks(const GridSpec& spec)
{
  std::vector<Block> blocks;
  for (int t = 0; t < spec.nt; t += kTopBlock)
  {
    for (int y = 0; y < spec.ny; y += kTopBlock)
    {
      for (int x = 0; x < spec.nx; x += kTopBlock)
      {
        blocks.push_back(topBlockOf(spec, x, y, t));
      }
    }
  }
  return blocks;
}

/// The verdicts (ascending voxel) on @p members, block by block.
template <typename Members>
std::vector<VoxelVerdict> screenMembers(const GridSpec& spec, const std::vector<Block>& blocks, const Members& members,
                                        int needed, bool with_failed, const BoxScreen& screen)
{
  std::vector<std::vector<VoxelVerdict>> found(blocks.size());
#pragma omp parallel num_threads(screen.threads) if (blocks.size() >= 16)
  {
    BlockSearch<Members> search(spec, members, needed, with_failed, screen);
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

std::vector<VoxelVerdict> screenVoxels(const GridSpec& spec, const VoxelSet& members,
                                       const std::vector<std::size_t>& voxels, int needed, const BoxScreen& screen)
{
  return screenMembers(spec, topBlocksOf(spec, voxels), SetMembers(members), needed, true, screen);
}

std::vector<LeafBox> reachingLeaves(const GridSpec& spec, const std::vector<std::uint8_t>& count, int target,
                                    const BoxScreen& screen)
{
  const int needed = std::clamp(target, 0, 255);
  std::vector<LeafBox> leaves;
  for (const VoxelVerdict& v :
       screenMembers(spec, topBlocks(spec), CountMembers(count, spec, needed), needed, false, screen))
  {
    leaves.push_back(voxelLeaf(spec, v.voxel, std::min<int>(count[v.voxel], v.bound)));
  }
  return leaves;
}

}  // namespace core
}  // namespace fdml_localization
