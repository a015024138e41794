#include "fdml_localization/core/localization/level_masks.h"

#include "fdml_localization/core/localization/count_scan.h"

#include <algorithm>
#include <cstring>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
using Word = std::uint64_t;

/// @p g spread towards higher bits through the consecutive bits of @p p (a Kogge-Stone occluded
/// fill: each step doubles the reach).
Word fillUp(Word g, Word p)
{
  for (int shift = 1; shift < 64; shift *= 2)
  {
    g |= p & (g << shift);
    p &= p << shift;
  }
  return g;
}

/// fillUp() towards lower bits.
Word fillDown(Word g, Word p)
{
  for (int shift = 1; shift < 64; shift *= 2)
  {
    g |= p & (g >> shift);
    p &= p >> shift;
  }
  return g;
}

std::size_t popcount(Word w)
{
  return static_cast<std::size_t>(__builtin_popcountll(w));
}
}  // namespace

LevelMasks::LevelMasks(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level, int top)
  : spec_(spec)
  , count_(count)
  , level_(level)
  , top_(top)
  , words_((static_cast<std::size_t>(std::max(spec.nx, 0)) + 63) / 64)
  , level_bits_(static_cast<std::size_t>(std::max(spec.ny, 0)) * std::max(spec.nt, 0) * words_, 0)
  , built_(static_cast<std::size_t>(std::max(spec.ny, 0)) * std::max(spec.nt, 0), 0)
  , reached_(level_bits_.size(), 0)
  , queued_(built_.size(), 0)
  , runs_(words_, 0)
  , spread_(words_, 0)
  , seeds_(words_, 0)
{
  if (count.size() != spec.voxelCount())
  {
    throw std::invalid_argument("LevelMasks: the count field does not match the grid");
  }
}

const LevelMasks::Word* LevelMasks::levelOf(std::size_t row)
{
  Word* bits = level_bits_.data() + row * words_;
  if (!built_[row])
  {
    built_[row] = 1;
    const std::uint8_t* c = count_.data() + row * static_cast<std::size_t>(spec_.nx);
    int x = 0;
    if (level_ >= 1 && level_ <= 128 && (top_ >= 255 || top_ < 128))
    {
      for (; x + 8 <= spec_.nx; x += 8)  // eight voxels at a time
      {
        std::uint64_t word = 0;
        std::memcpy(&word, c + x, 8);
        unsigned in = bytesAtLeast(word, static_cast<unsigned>(level_));
        in &= top_ >= 255 ? 0xffu : ~bytesAtLeast(word, static_cast<unsigned>(std::max(top_ + 1, 1)));
        bits[x >> 6] |= static_cast<Word>(in) << (x & 63);
      }
    }
    for (; x < spec_.nx; ++x)
    {
      bits[x >> 6] |= static_cast<Word>(c[x] >= level_ && c[x] <= top_) << (x & 63);
    }
  }
  return bits;
}

std::size_t LevelMasks::fill(std::size_t row, const Word* seeds)
{
  const Word* level = levelOf(row);
  Word* reached = reached_.data() + row * words_;
  // Runs are intervals: each of their voxels lies above or below a seed of theirs.
  std::vector<Word>& runs = runs_;
  Word carry = 0;  // the fill reached the previous word's top voxel
  for (std::size_t w = 0; w < words_; ++w)
  {
    runs[w] = fillUp((seeds[w] & level[w]) | (carry & level[w]), level[w]);
    carry = runs[w] >> 63;
  }
  carry = 0;
  for (std::size_t w = words_; w-- > 0;)
  {
    runs[w] |= fillDown((seeds[w] & level[w]) | ((carry << 63) & level[w]), level[w]);
    carry = runs[w] & 1;
  }
  std::size_t added = 0;
  for (std::size_t w = 0; w < words_; ++w)
  {
    const Word fresh = runs[w] & ~reached[w];
    reached[w] |= fresh;
    added += popcount(fresh);
  }
  if (added > 0 && !queued_[row])
  {
    queued_[row] = 1;
    stack_.push_back(row);
  }
  return added;
}

std::size_t LevelMasks::flood(std::size_t row, int x)
{
  std::vector<Word> seed(words_, 0);
  seed[static_cast<std::size_t>(x) >> 6] = Word{ 1 } << (x & 63);
  ++floods_;
  const std::size_t voxels = fill(row, seed.data());
  return voxels + spread();
}

template <typename Fn>
void LevelMasks::forEachRowAround(std::size_t row, bool self, Fn&& fn) const
{
  const std::size_t ny = static_cast<std::size_t>(spec_.ny);
  const int iy = static_cast<int>(row % ny);
  const int it = static_cast<int>(row / ny);
  for (int dt = -1; dt <= 1; ++dt)
  {
    const int t = (it + dt + spec_.nt) % spec_.nt;
    for (int dy = -1; dy <= 1; ++dy)
    {
      const int y = iy + dy;
      const std::size_t next = static_cast<std::size_t>(t) * ny + static_cast<std::size_t>(y);
      if (y >= 0 && y < spec_.ny && (self || next != row))
      {
        fn(next);
      }
    }
  }
}

std::size_t LevelMasks::spreadFrom(const Word* from, std::size_t row, bool self)
{
  // The row's voxels and their neighbours along x.
  for (std::size_t w = 0; w < words_; ++w)
  {
    spread_[w] = from[w] | (from[w] << 1) | (from[w] >> 1) | (w > 0 ? from[w - 1] >> 63 : 0) |
                 (w + 1 < words_ ? from[w + 1] << 63 : 0);
  }
  std::size_t voxels = 0;
  forEachRowAround(row, self, [&](std::size_t next) {
    const Word* level = levelOf(next);
    const Word* reached = reached_.data() + next * words_;
    Word any = 0;
    for (std::size_t w = 0; w < words_; ++w)
    {
      seeds_[w] = spread_[w] & level[w] & ~reached[w];
      any |= seeds_[w];
    }
    voxels += any != 0 ? fill(next, seeds_.data()) : 0;
  });
  return voxels;
}

std::size_t LevelMasks::spread()
{
  std::size_t voxels = 0;
  while (!stack_.empty())
  {
    const std::size_t r = stack_.back();
    stack_.pop_back();
    queued_[r] = 0;
    // A row's own runs never touch (a gap lies between them).
    voxels += spreadFrom(reached_.data() + r * words_, r, false);
  }
  return voxels;
}

std::size_t LevelMasks::floodNeighboursOf(LevelMasks& source)
{
  std::size_t voxels = 0;
  for (std::size_t row = 0; row < built_.size(); ++row)
  {
    const Word* from = source.levelOf(row);
    if (std::any_of(from, from + words_, [](Word w) { return w != 0; }))
    {
      voxels += spreadFrom(from, row, true);
      voxels += spread();
    }
  }
  return voxels;
}

std::vector<std::size_t> LevelMasks::floodedVoxels() const
{
  std::vector<std::size_t> voxels;
  const std::size_t nx = static_cast<std::size_t>(spec_.nx);
  for (std::size_t row = 0; row < built_.size(); ++row)
  {
    for (std::size_t w = 0; w < words_; ++w)
    {
      for (Word bits = reached_[row * words_ + w]; bits != 0; bits &= bits - 1)
      {
        voxels.push_back(row * nx + 64 * w + static_cast<std::size_t>(__builtin_ctzll(bits)));
      }
    }
  }
  return voxels;
}

std::size_t LevelMasks::floodEach(const std::vector<std::size_t>& voxels, std::vector<std::size_t>& sizes)
{
  const std::size_t nx = static_cast<std::size_t>(spec_.nx);
  auto reached = [&](std::size_t v) {
    const std::size_t x = v % nx;
    return ((reached_[(v / nx) * words_ + x / 64] >> (x % 64)) & 1) != 0;
  };
  // The voxels not yet in a flooded component (each component is flooded once: the voxels it
  // holds are found in it right after).
  std::vector<std::size_t> open;
  for (std::size_t k = 0; k < voxels.size(); ++k)
  {
    if (voxels[k] < count_.size() && count_[voxels[k]] >= level_ && !reached(voxels[k]))
    {
      open.push_back(k);
    }
  }
  const std::size_t before = floods_;
  while (!open.empty())
  {
    const std::size_t v = voxels[open.front()];
    const std::size_t size = flood(v / nx, static_cast<int>(v % nx));
    const auto rest = std::partition(open.begin(), open.end(), [&](std::size_t k) { return !reached(voxels[k]); });
    for (auto it = rest; it != open.end(); ++it)
    {
      sizes[*it] = size;
    }
    open.erase(rest, open.end());
  }
  return floods_ - before;
}

std::vector<std::size_t> LevelMasks::componentSizes(const std::vector<std::size_t>& voxels)
{
  std::vector<std::size_t> sizes(voxels.size(), 0);
  floodEach(voxels, sizes);
  return sizes;
}

std::size_t LevelMasks::componentCount(const std::vector<std::size_t>& voxels, std::size_t& holding)
{
  std::vector<std::size_t> sizes(voxels.size(), 0);
  holding = floodEach(voxels, sizes);
  for (std::size_t row = 0; row < built_.size(); ++row)
  {
    for (std::size_t w = 0; w < words_; ++w)
    {
      // The row's voxels reaching the level that no flood reached yet start new components.
      for (Word open = levelOf(row)[w] & ~reached_[row * words_ + w]; open != 0;
           open = levelOf(row)[w] & ~reached_[row * words_ + w])
      {
        flood(row, static_cast<int>(64 * w) + __builtin_ctzll(open));
      }
    }
  }
  return floods_;
}

}  // namespace core
}  // namespace fdml_localization
