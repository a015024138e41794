#include "fdml_localization/core/localization/components.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Visited flags, one bit per voxel.
class BitFlags
{
public:
  explicit BitFlags(std::size_t n) : words_((n + 63) / 64, 0)
  {}
  bool test(std::size_t v) const
  {
    return (words_[v >> 6] >> (v & 63)) & 1u;
  }
  void set(std::size_t v)
  {
    words_[v >> 6] |= std::uint64_t(1) << (v & 63);
  }

private:
  std::vector<std::uint64_t> words_;
};

/// Breadth-first flood of the voxels accepted by @p inside, from @p seed (already accepted).
template <typename Inside, typename Visit>
void flood(const GridSpec& spec, std::size_t seed, BitFlags& visited, std::vector<std::size_t>& queue, Inside&& inside,
           Visit&& visit)
{
  queue.clear();
  queue.push_back(seed);
  visited.set(seed);
  for (std::size_t head = 0; head < queue.size(); ++head)
  {
    const std::size_t v = queue[head];
    visit(v);
    int ix = 0;
    int iy = 0;
    int it = 0;
    spec.unindex(v, ix, iy, it);
    forEachNeighbour(spec, ix, iy, it, [&](std::size_t u) {
      if (!visited.test(u) && inside(u))
      {
        visited.set(u);
        queue.push_back(u);
      }
    });
  }
}
}  // namespace

void computeCentroid(const GridSpec& spec, VoxelCluster& cluster)
{
  if (cluster.voxels.empty())
  {
    return;
  }
  double sx = 0.0;
  double sy = 0.0;
  double sc = 0.0;
  double ss = 0.0;
  for (std::size_t v : cluster.voxels)
  {
    const Pose2 c = spec.centre(v);
    sx += c.x;
    sy += c.y;
    sc += std::cos(c.theta);
    ss += std::sin(c.theta);
  }
  const double n = static_cast<double>(cluster.voxels.size());
  cluster.centroid = Pose2(sx / n, sy / n, wrapAngle(std::atan2(ss, sc)));
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t v : cluster.voxels)
  {
    const Pose2 c = spec.centre(v);
    const double dx = (c.x - cluster.centroid.x) / spec.cell;
    const double dy = (c.y - cluster.centroid.y) / spec.cell;
    const double dt = angleDiff(c.theta, cluster.centroid.theta) / spec.thetaStep();
    const double d2 = dx * dx + dy * dy + dt * dt;
    if (d2 < best)
    {
      best = d2;
      cluster.representative = v;
    }
  }
}

std::vector<VoxelCluster> connectedComponents(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level)
{
  std::vector<VoxelCluster> clusters;
  BitFlags visited(count.size());
  std::vector<std::size_t> queue;
  auto inside = [&](std::size_t u) { return count[u] >= level; };
  for (std::size_t v = 0; v < count.size(); ++v)
  {
    if (count[v] < level || visited.test(v))
    {
      continue;
    }
    VoxelCluster cluster;
    flood(spec, v, visited, queue, inside,
          [&](std::size_t u) { cluster.peak_count = std::max<int>(cluster.peak_count, count[u]); });
    cluster.voxels = queue;
    computeCentroid(spec, cluster);
    clusters.push_back(std::move(cluster));
  }
  std::stable_sort(clusters.begin(), clusters.end(), [](const VoxelCluster& a, const VoxelCluster& b) {
    return a.peak_count != b.peak_count ? a.peak_count > b.peak_count : a.voxels.size() > b.voxels.size();
  });
  return clusters;
}

std::size_t componentSize(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level, std::size_t seed)
{
  if (seed >= count.size() || count[seed] < level)
  {
    return 0;
  }
  BitFlags visited(count.size());
  std::vector<std::size_t> queue;
  flood(
      spec, seed, visited, queue, [&](std::size_t u) { return count[u] >= level; }, [](std::size_t) {});
  return queue.size();
}

std::vector<std::size_t> componentSizes(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                        const std::vector<std::size_t>& seeds)
{
  std::vector<std::size_t> sizes(seeds.size(), 0);
  BitFlags visited(count.size());
  std::vector<std::size_t> queue;
  for (std::size_t i = 0; i < seeds.size(); ++i)
  {
    const std::size_t seed = seeds[i];
    if (seed >= count.size() || count[seed] < level || visited.test(seed))
    {
      continue;
    }
    flood(
        spec, seed, visited, queue, [&](std::size_t u) { return count[u] >= level; }, [](std::size_t) {});
    // Every later seed flooded now lies in this component.
    for (std::size_t j = i; j < seeds.size(); ++j)
    {
      if (sizes[j] == 0 && seeds[j] < count.size() && visited.test(seeds[j]))
      {
        sizes[j] = queue.size();
      }
    }
  }
  return sizes;
}

std::vector<VoxelCluster> regionalMaxima(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                         const std::vector<std::size_t>& candidates)
{
  std::vector<VoxelCluster> clusters;
  BitFlags visited(count.size());
  std::vector<std::size_t> queue;
  for (std::size_t v : candidates)
  {
    if (visited.test(v) || count[v] != level)
    {
      continue;
    }
    bool is_maximum = true;
    flood(
        spec, v, visited, queue, [&](std::size_t u) { return count[u] == level; },
        [&](std::size_t u) {
          if (!is_maximum)
          {
            return;
          }
          int ix = 0;
          int iy = 0;
          int it = 0;
          spec.unindex(u, ix, iy, it);
          forEachNeighbour(spec, ix, iy, it, [&](std::size_t w) {
            if (count[w] > level)
            {
              is_maximum = false;
            }
          });
        });
    if (!is_maximum)
    {
      continue;
    }
    VoxelCluster cluster;
    cluster.voxels = queue;
    cluster.peak_count = level;
    computeCentroid(spec, cluster);
    clusters.push_back(std::move(cluster));
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const VoxelCluster& a, const VoxelCluster& b) { return a.voxels.size() > b.voxels.size(); });
  return clusters;
}

namespace
{
/// Whether any of the 8 bytes of @p word is at least @p lo (1 <= lo <= 128): a byte above
/// lo - 1 carries into its top bit (no carry crosses a byte below 128), and a byte of 128 or
/// more already has it.
bool anyByteAtLeast(std::uint64_t word, unsigned lo)
{
  constexpr std::uint64_t kOnes = 0x0101010101010101ull;
  constexpr std::uint64_t kTops = 0x8080808080808080ull;
  return (((word + kOnes * (128u - lo)) | word) & kTops) != 0;
}

/// Calls @p fn(v) for every voxel v (ascending) whose count lies in [lo, hi], lo >= 1.
template <typename Fn>
void forEachVoxelIn(const std::vector<std::uint8_t>& count, unsigned lo, unsigned hi, Fn&& fn)
{
  const std::size_t n = count.size();
  std::size_t v = 0;
  if (lo > 255u || lo > hi)
  {
    return;
  }
  if (lo <= 128u)
  {
    // Skip 8 voxels at a time while none reaches lo.
    for (; v + 8 <= n; v += 8)
    {
      std::uint64_t word = 0;
      std::memcpy(&word, count.data() + v, 8);
      if (!anyByteAtLeast(word, lo))
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
  for (; v < n; ++v)
  {
    if (count[v] >= lo && count[v] <= hi)
    {
      fn(v);
    }
  }
}
}  // namespace

std::vector<std::vector<std::size_t>> voxelsByCount(const std::vector<std::uint8_t>& count, int min_level,
                                                    int max_level)
{
  std::vector<std::vector<std::size_t>> buckets(static_cast<std::size_t>(std::max(max_level, 0)) + 1);
  if (max_level < 1)
  {
    return buckets;
  }
  const auto lo = static_cast<unsigned>(std::clamp(min_level, 1, 256));
  forEachVoxelIn(count, lo, static_cast<unsigned>(std::min(max_level, 255)),
                 [&](std::size_t v) { buckets[count[v]].push_back(v); });
  return buckets;
}

std::vector<std::size_t> voxelsAtLeast(const std::vector<std::uint8_t>& count, int level)
{
  std::vector<std::size_t> voxels;
  if (level <= 0)
  {
    voxels.resize(count.size());
    std::iota(voxels.begin(), voxels.end(), std::size_t{ 0 });
    return voxels;
  }
  forEachVoxelIn(count, static_cast<unsigned>(std::min(level, 256)), 255u, [&](std::size_t v) { voxels.push_back(v); });
  return voxels;
}

}  // namespace core
}  // namespace fdml_localization
