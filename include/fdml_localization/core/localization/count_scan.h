/**
 * @file count_scan.h
 * @brief Scans of a count field (one byte per voxel, GridSpec::index order) eight voxels at a
 *        time: word tests of eight counts, and the voxels of each count.
 */
#pragma once

#include <cstddef>
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// Whether any of the 8 bytes of @p word is at least @p lo (1 <= lo <= 128): a byte above
/// lo - 1 carries into its top bit (no carry crosses a byte below 128), and a byte of 128 or
/// more already has it. Eight counts tested at once.
bool anyByteAtLeast(std::uint64_t word, unsigned lo);

/// The bytes of @p word at least @p lo (1 <= lo <= 128) as a mask, byte i (from the least
/// significant) giving bit i: each byte with its top bit set minus lo cannot borrow from the
/// next, and a byte of 128 or more has the top bit already.
unsigned bytesAtLeast(std::uint64_t word, unsigned lo);

/// Whether any of the 8 bytes of @p word equals @p value (<= 255): some byte of word ^ value
/// is zero.
bool anyByteEqual(std::uint64_t word, unsigned value);

/// Calls @p fn(v) for every voxel v in [first, end) (ascending) whose count lies in [lo, hi],
/// skipping eight voxels at a time that hold none (hi == lo: none equal to it; lo = 0 skips
/// none). The one scan of a count field by level.
template <typename Fn>
void forEachVoxelIn(const std::vector<std::uint8_t>& count, std::size_t first, std::size_t end, unsigned lo,
                    unsigned hi, Fn&& fn)
{
  std::size_t v = first;
  end = std::min(end, count.size());
  if (lo > 255u || lo > hi)
  {
    return;
  }
  if (lo <= 128u)
  {
    for (; v + 8 <= end; v += 8)
    {
      std::uint64_t word = 0;
      std::memcpy(&word, count.data() + v, 8);
      if (lo == hi ? !anyByteEqual(word, lo) : !anyByteAtLeast(word, lo))
      {
        continue;
      }
      for (std::size_t j = v; j < v + 8; ++j)
      {
        if (count[j] >= lo && count[j] <= hi)
        {
          fn(j);
        }
      }
    }
  }
  for (; v < end; ++v)
  {
    if (count[v] >= lo && count[v] <= hi)
    {
      fn(v);
    }
  }
}

/// The voxels of each count value: result[c] lists the voxels (ascending) with count c, for
/// max(min_level, 1) <= c <= max_level.
std::vector<std::vector<std::size_t>> voxelsByCount(const std::vector<std::uint8_t>& count, int min_level,
                                                    int max_level);

/// Appends to @p out the voxels v in [first, end) (ascending) whose count is @p level (1 to 255).
void appendVoxelsAt(const std::vector<std::uint8_t>& count, std::size_t first, std::size_t end, int level,
                    std::vector<std::size_t>& out);

}  // namespace core
}  // namespace fdml_localization
