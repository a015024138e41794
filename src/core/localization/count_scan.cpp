#include "fdml_localization/core/localization/count_scan.h"

#include <algorithm>
#include <cstring>

namespace fdml_localization
{
namespace core
{
bool anyByteAtLeast(std::uint64_t word, unsigned lo)
{
  constexpr std::uint64_t kOnes = 0x0101010101010101ull;
  constexpr std::uint64_t kTops = 0x8080808080808080ull;
  return (((word + kOnes * (128u - lo)) | word) & kTops) != 0;
}

unsigned bytesAtLeast(std::uint64_t word, unsigned lo)
{
  constexpr std::uint64_t kOnes = 0x0101010101010101ull;
  constexpr std::uint64_t kTops = 0x8080808080808080ull;
  const std::uint64_t tops = (((word | kTops) - kOnes * lo) | word) & kTops;
  // Gathers the eight top bits (at 8 i + 7) into the top byte, in order.
  return static_cast<unsigned>(((tops >> 7) * 0x0102040810204080ull) >> 56);
}

bool anyByteEqual(std::uint64_t word, unsigned value)
{
  constexpr std::uint64_t kOnes = 0x0101010101010101ull;
  constexpr std::uint64_t kTops = 0x8080808080808080ull;
  const std::uint64_t x = word ^ (kOnes * value);
  return ((x - kOnes) & ~x & kTops) != 0;
}

std::vector<std::vector<std::size_t>> voxelsByCount(const std::vector<std::uint8_t>& count, int min_level,
                                                    int max_level)
{
  std::vector<std::vector<std::size_t>> buckets(static_cast<std::size_t>(std::max(max_level, 0)) + 1);
  if (max_level < 1)
  {
    return buckets;
  }
  const auto lo = static_cast<unsigned>(std::clamp(min_level, 1, 256));
  forEachVoxelIn(count, 0, count.size(), lo, static_cast<unsigned>(std::min(max_level, 255)),
                 [&](std::size_t v) { buckets[count[v]].push_back(v); });
  return buckets;
}

void appendVoxelsAt(const std::vector<std::uint8_t>& count, std::size_t first, std::size_t end, int level,
                    std::vector<std::size_t>& out)
{
  if (level < 1 || level > 255)
  {
    return;
  }
  const auto value = static_cast<unsigned>(level);
  forEachVoxelIn(count, first, end, value, value, [&](std::size_t v) { out.push_back(v); });
}

}  // namespace core
}  // namespace fdml_localization
