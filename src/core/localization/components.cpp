#include "fdml_localization/core/localization/components.h"

#include "fdml_localization/core/localization/count_scan.h"
#include "fdml_localization/core/localization/level_masks.h"

#include <algorithm>
#include <cmath>
#include <limits>

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

/// forEachNeighbour() of voxel @p v, in the same order, until @p fn returns false; interior
/// voxels by fixed index offsets.
class Neighbours
{
public:
  explicit Neighbours(const GridSpec& spec) : spec_(spec)
  {
    const long nx = spec.nx;
    const long plane = nx * spec.ny;
    for (long dt = -1; dt <= 1; ++dt)
    {
      for (long dy = -1; dy <= 1; ++dy)
      {
        for (long dx = -1; dx <= 1; ++dx)
        {
          if (dx != 0 || dy != 0 || dt != 0)
          {
            offsets_.push_back(dt * plane + dy * nx + dx);
          }
        }
      }
    }
  }

  template <typename Fn>
  void until(std::size_t v, Fn&& fn) const
  {
    int ix = 0;
    int iy = 0;
    int it = 0;
    spec_.unindex(v, ix, iy, it);
    if (ix > 0 && ix + 1 < spec_.nx && iy > 0 && iy + 1 < spec_.ny && it > 0 && it + 1 < spec_.nt)
    {
      for (long d : offsets_)
      {
        if (!fn(static_cast<std::size_t>(static_cast<long>(v) + d)))
        {
          return;
        }
      }
      return;
    }
    bool go = true;
    forEachNeighbour(spec_, ix, iy, it, [&](std::size_t w) { go = go && fn(w); });
  }

private:
  const GridSpec& spec_;
  std::vector<long> offsets_;
};

/// Breadth-first flood of the voxels accepted by @p inside, from @p seed (already accepted).
template <typename Inside, typename Visit>
void flood(const Neighbours& neighbours, std::size_t seed, BitFlags& visited, std::vector<std::size_t>& queue,
           Inside&& inside, Visit&& visit)
{
  queue.clear();
  queue.push_back(seed);
  visited.set(seed);
  for (std::size_t head = 0; head < queue.size(); ++head)
  {
    const std::size_t v = queue[head];
    visit(v);
    neighbours.until(v, [&](std::size_t u) {
      if (!visited.test(u) && inside(u))
      {
        visited.set(u);
        queue.push_back(u);
      }
      return true;
    });
  }
}

/// The plateaus of regionalMaxima() in the order they are found (first candidate first), without
/// centroids.
std::vector<VoxelCluster> regionalPlateaus(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                           const std::vector<std::size_t>& candidates)
{
  std::vector<VoxelCluster> clusters;
  // A flood stops at the first voxel above the level, or in a plateau already found not to be a
  // maximum (`lower`): its voxels join `lower`. Floods stay in their plateau, so a finished one
  // holds all of it, from the same first voxel and in the same order as a full flood.
  BitFlags seen(count.size());
  BitFlags lower(count.size());
  const Neighbours neighbours(spec);
  std::vector<std::size_t> queue;
  for (std::size_t v : candidates)
  {
    if (seen.test(v) || count[v] != level)
    {
      continue;
    }
    queue.assign(1, v);
    seen.set(v);
    bool is_maximum = true;
    for (std::size_t head = 0; head < queue.size() && is_maximum; ++head)
    {
      neighbours.until(queue[head], [&](std::size_t w) {
        if (count[w] < level)
        {
          return true;
        }
        if (count[w] > level || lower.test(w))
        {
          is_maximum = false;
          return false;
        }
        if (!seen.test(w))
        {
          seen.set(w);
          queue.push_back(w);
        }
        return true;
      });
    }
    if (!is_maximum)
    {
      for (std::size_t u : queue)
      {
        lower.set(u);
      }
      continue;
    }
    VoxelCluster cluster;
    cluster.voxels = queue;
    cluster.peak_count = level;
    clusters.push_back(std::move(cluster));
  }
  return clusters;
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
  // A large cluster reads its headings' cosines and sines from a table (the same values).
  std::vector<double> cosines;
  std::vector<double> sines;
  if (cluster.voxels.size() > static_cast<std::size_t>(spec.nt))
  {
    for (int it = 0; it < spec.nt; ++it)
    {
      cosines.push_back(std::cos(spec.centreTheta(it)));
      sines.push_back(std::sin(spec.centreTheta(it)));
    }
  }
  for (std::size_t v : cluster.voxels)
  {
    int ix = 0;
    int iy = 0;
    int it = 0;
    spec.unindex(v, ix, iy, it);
    sx += spec.centreX(ix);
    sy += spec.centreY(iy);
    const double theta = spec.centreTheta(it);
    sc += cosines.empty() ? std::cos(theta) : cosines[static_cast<std::size_t>(it)];
    ss += sines.empty() ? std::sin(theta) : sines[static_cast<std::size_t>(it)];
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
  const Neighbours neighbours(spec);
  std::vector<std::size_t> queue;
  auto inside = [&](std::size_t u) { return count[u] >= level; };
  // Every voxel reaching the level, ascending; a component starts at its first voxel.
  forEachVoxelIn(count, 0, count.size(), static_cast<unsigned>(std::clamp(level, 0, 256)), 255u, [&](std::size_t v) {
    if (visited.test(v))
    {
      return;
    }
    VoxelCluster cluster;
    flood(neighbours, v, visited, queue, inside,
          [&](std::size_t u) { cluster.peak_count = std::max<int>(cluster.peak_count, count[u]); });
    cluster.voxels = queue;
    computeCentroid(spec, cluster);
    clusters.push_back(std::move(cluster));
  });
  std::stable_sort(clusters.begin(), clusters.end(), [](const VoxelCluster& a, const VoxelCluster& b) {
    return a.peak_count != b.peak_count ? a.peak_count > b.peak_count : a.voxels.size() > b.voxels.size();
  });
  return clusters;
}

std::size_t componentSize(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level, std::size_t seed)
{
  return componentSizes(spec, count, level, { seed }).front();
}

std::vector<std::size_t> componentSizes(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                        const std::vector<std::size_t>& seeds)
{
  return LevelMasks(spec, count, level).componentSizes(seeds);
}

std::vector<std::size_t> liftNonMaximalPlateaus(const GridSpec& spec, std::vector<std::uint8_t>& count, int level)
{
  std::vector<std::size_t> lifted;
  if (level < 0 || level > 254)
  {
    return lifted;
  }
  // Flooded as bit masks: the voxels at the level from those beside a voxel above it.
  LevelMasks at(spec, count, level, level);
  LevelMasks higher(spec, count, level + 1);
  at.floodNeighboursOf(higher);
  lifted = at.floodedVoxels();
  for (std::size_t v : lifted)
  {
    count[v] = static_cast<std::uint8_t>(level + 1);
  }
  return lifted;
}

std::vector<VoxelCluster> regionalMaxima(const GridSpec& spec, const std::vector<std::uint8_t>& count, int level,
                                         const std::vector<std::size_t>& candidates)
{
  std::vector<VoxelCluster> clusters = regionalPlateaus(spec, count, level, candidates);
  for (VoxelCluster& cluster : clusters)
  {
    computeCentroid(spec, cluster);
  }
  std::stable_sort(clusters.begin(), clusters.end(),
                   [](const VoxelCluster& a, const VoxelCluster& b) { return a.voxels.size() > b.voxels.size(); });
  return clusters;
}

}  // namespace core
}  // namespace fdml_localization
