#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Union-find over leaf indices.
class DisjointSets
{
public:
  explicit DisjointSets(std::size_t n) : parent_(n)
  {
    std::iota(parent_.begin(), parent_.end(), 0);
  }
  std::size_t find(std::size_t i)
  {
    while (parent_[i] != i)
    {
      parent_[i] = parent_[parent_[i]];
      i = parent_[i];
    }
    return i;
  }
  void unite(std::size_t a, std::size_t b)
  {
    parent_[find(a)] = find(b);
  }

private:
  std::vector<std::size_t> parent_;
};

std::uint64_t cellKey(std::int64_t ix, std::int64_t iy, std::int64_t it)
{
  return (static_cast<std::uint64_t>(ix) << 42) ^ (static_cast<std::uint64_t>(iy) << 21) ^
         static_cast<std::uint64_t>(it);
}

/// Unites every pair of 26-neighbours among @p members (theta periodic).
void uniteNeighbours(const std::vector<LeafBox>& leaves, const std::vector<std::size_t>& members,
                     std::int64_t theta_cells, DisjointSets& sets)
{
  std::unordered_map<std::uint64_t, std::size_t> index;
  index.reserve(members.size() * 2);
  for (const std::size_t i : members)
  {
    index.emplace(cellKey(leaves[i].ix, leaves[i].iy, leaves[i].it), i);
  }
  for (const std::size_t i : members)
  {
    const LeafBox& l = leaves[i];
    for (int dt = -1; dt <= 1; ++dt)
    {
      const std::int64_t t = ((l.it + dt) % theta_cells + theta_cells) % theta_cells;
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dx = -1; dx <= 1; ++dx)
        {
          if (l.ix + dx < 0 || l.iy + dy < 0)
          {
            continue;
          }
          const auto found = index.find(cellKey(l.ix + dx, l.iy + dy, t));
          if (found != index.end())
          {
            sets.unite(i, found->second);
          }
        }
      }
    }
  }
}

/// Mean position and circular-mean heading of the leaves' centres; the leaf nearest to it.
LeafCluster plateauCluster(const std::vector<LeafBox>& leaves, const std::vector<std::size_t>& members)
{
  LeafCluster c;
  double sx = 0.0, sy = 0.0, ss = 0.0, sc = 0.0;
  for (const std::size_t i : members)
  {
    const Pose2 p = leaves[i].box.centre();
    sx += p.x;
    sy += p.y;
    ss += std::sin(p.theta);
    sc += std::cos(p.theta);
  }
  const double n = static_cast<double>(members.size());
  c.centroid = Pose2(sx / n, sy / n, std::atan2(ss, sc));
  double best = kInf;
  for (const std::size_t i : members)
  {
    const Pose2 p = leaves[i].box.centre();
    const double d =
        (p.position() - c.centroid.position()).squaredNorm() + std::pow(angleDiff(p.theta, c.centroid.theta), 2);
    if (d < best)
    {
      best = d;
      c.representative = i;
    }
  }
  return c;
}
/// One cluster per connected plateau of the peak count of @p component (a connected component).
void addPlateauClusters(const std::vector<LeafBox>& leaves, const std::vector<std::size_t>& component,
                        std::int64_t theta_cells, std::vector<LeafCluster>& clusters)
{
  int peak = 0;
  for (const std::size_t i : component)
  {
    peak = std::max(peak, leaves[i].count);
  }
  std::vector<std::size_t> plateau;
  for (const std::size_t i : component)
  {
    if (leaves[i].count == peak)
    {
      plateau.push_back(i);
    }
  }
  DisjointSets plateaus(leaves.size());
  uniteNeighbours(leaves, plateau, theta_cells, plateaus);
  std::unordered_map<std::size_t, std::vector<std::size_t>> parts;
  for (const std::size_t i : plateau)
  {
    parts[plateaus.find(i)].push_back(i);
  }
  for (auto& part : parts)
  {
    LeafCluster c = plateauCluster(leaves, part.second);
    c.size = component.size();
    c.peak_count = peak;
    clusters.push_back(c);
  }
}

/**
 * Unites the plateau leaves (count == @p level) with their neighbours of the same count and
 * marks those touching a leaf of a higher count (@p index: every leaf with count >= level).
 */
void unitePlateau(const std::vector<LeafBox>& leaves, const std::vector<std::size_t>& plateau,
                  const std::unordered_map<std::uint64_t, std::size_t>& index, int level, std::int64_t theta_cells,
                  DisjointSets& sets, std::vector<char>& dominated)
{
  for (const std::size_t i : plateau)
  {
    const LeafBox& l = leaves[i];
    for (int dt = -1; dt <= 1; ++dt)
    {
      const std::int64_t t = ((l.it + dt) % theta_cells + theta_cells) % theta_cells;
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dx = -1; dx <= 1; ++dx)
        {
          const auto found = index.find(cellKey(l.ix + dx, l.iy + dy, t));
          if (l.ix + dx < 0 || l.iy + dy < 0 || found == index.end())
          {
            continue;
          }
          if (leaves[found->second].count > level)
          {
            dominated[i] = 1;
          }
          else
          {
            sets.unite(i, found->second);
          }
        }
      }
    }
  }
}
}  // namespace

std::vector<LeafCluster> clusterLeaves(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells)
{
  std::vector<std::size_t> members;
  for (std::size_t i = 0; i < leaves.size(); ++i)
  {
    if (leaves[i].count >= level)
    {
      members.push_back(i);
    }
  }
  DisjointSets components(leaves.size());
  uniteNeighbours(leaves, members, theta_cells, components);
  std::unordered_map<std::size_t, std::vector<std::size_t>> by_root;
  for (const std::size_t i : members)
  {
    by_root[components.find(i)].push_back(i);
  }
  std::vector<LeafCluster> clusters;
  for (auto& entry : by_root)
  {
    addPlateauClusters(leaves, entry.second, theta_cells, clusters);
  }
  // Deterministic order: highest peak, then largest component, then position.
  std::sort(clusters.begin(), clusters.end(), [](const LeafCluster& a, const LeafCluster& b) {
    if (a.peak_count != b.peak_count)
    {
      return a.peak_count > b.peak_count;
    }
    if (a.size != b.size)
    {
      return a.size > b.size;
    }
    return a.representative < b.representative;
  });
  return clusters;
}

std::vector<LeafCluster> leafMaxima(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells)
{
  std::unordered_map<std::uint64_t, std::size_t> index;
  std::vector<std::size_t> plateau;
  for (std::size_t i = 0; i < leaves.size(); ++i)
  {
    if (leaves[i].count >= level)
    {
      index.emplace(cellKey(leaves[i].ix, leaves[i].iy, leaves[i].it), i);
    }
    if (leaves[i].count == level)
    {
      plateau.push_back(i);
    }
  }
  DisjointSets sets(leaves.size());
  std::vector<char> dominated(leaves.size(), 0);
  unitePlateau(leaves, plateau, index, level, theta_cells, sets, dominated);
  std::unordered_map<std::size_t, std::vector<std::size_t>> parts;
  for (const std::size_t i : plateau)
  {
    parts[sets.find(i)].push_back(i);
  }
  std::vector<LeafCluster> maxima;
  for (auto& part : parts)
  {
    std::vector<std::size_t>& members = part.second;
    if (std::any_of(members.begin(), members.end(), [&](std::size_t i) { return dominated[i] != 0; }))
    {
      continue;
    }
    std::sort(members.begin(), members.end());
    LeafCluster c = plateauCluster(leaves, members);
    c.size = members.size();
    c.peak_count = level;
    c.members = std::move(members);
    maxima.push_back(std::move(c));
  }
  // Deterministic order: largest plateau first, then position.
  std::sort(maxima.begin(), maxima.end(), [](const LeafCluster& a, const LeafCluster& b) {
    return a.size != b.size ? a.size > b.size : a.representative < b.representative;
  });
  return maxima;
}

std::vector<std::size_t> leavesToSearch(const std::vector<LeafBox>& leaves, const std::vector<int>& labels, int target,
                                        std::size_t limit)
{
  std::vector<std::size_t> beyond, at;
  for (std::size_t l = 0; l < leaves.size() && l < labels.size(); ++l)
  {
    if (labels[l] >= 0)
    {
      (leaves[l].count > target ? beyond : at).push_back(l);
    }
  }
  std::stable_sort(beyond.begin(), beyond.end(),
                   [&](std::size_t a, std::size_t b) { return leaves[a].count > leaves[b].count; });
  // Whole bounds while they fit; the one that overflows spread over its leaves (taken in index
  // order they would all lie at one end of the map).
  std::vector<std::size_t> chosen;
  for (std::size_t first = 0; first < beyond.size() && chosen.size() < limit;)
  {
    std::size_t last = first;
    while (last < beyond.size() && leaves[beyond[last]].count == leaves[beyond[first]].count)
    {
      ++last;
    }
    const std::size_t room = limit - chosen.size();
    const std::size_t step = (last - first + room - 1) / room;
    for (std::size_t j = first; j < last; j += step)
    {
      chosen.push_back(beyond[j]);
    }
    first = last;
  }
  const std::size_t step = std::max<std::size_t>(1, at.size() / std::max<std::size_t>(1, limit));
  for (std::size_t j = 0; j < at.size(); j += step)
  {
    chosen.push_back(at[j]);
  }
  return chosen;
}

std::vector<int> leafComponents(const std::vector<LeafBox>& leaves, int level, std::int64_t theta_cells,
                                int& components)
{
  std::vector<std::size_t> members;
  for (std::size_t i = 0; i < leaves.size(); ++i)
  {
    if (leaves[i].count >= level)
    {
      members.push_back(i);
    }
  }
  DisjointSets sets(leaves.size());
  uniteNeighbours(leaves, members, theta_cells, sets);
  std::vector<int> labels(leaves.size(), -1);
  std::unordered_map<std::size_t, int> label_of_root;
  for (const std::size_t i : members)
  {
    const auto found = label_of_root.emplace(sets.find(i), static_cast<int>(label_of_root.size()));
    labels[i] = found.first->second;
  }
  components = static_cast<int>(label_of_root.size());
  return labels;
}

std::int64_t thetaCells(double cell_theta)
{
  return std::max<std::int64_t>(1, std::llround(kTwoPi / cell_theta));
}

PoseBox voxelBox(const GridSpec& spec, std::size_t v)
{
  int ix = 0, iy = 0, it = 0;
  spec.unindex(v, ix, iy, it);
  PoseBox box;
  box.x0 = spec.origin_x + ix * spec.cell;
  box.x1 = box.x0 + spec.cell;
  box.y0 = spec.origin_y + iy * spec.cell;
  box.y1 = box.y0 + spec.cell;
  box.t0 = -kPi + it * spec.thetaStep();
  box.t1 = box.t0 + spec.thetaStep();
  return box;
}

LeafBox voxelLeaf(const GridSpec& spec, std::size_t v, int count)
{
  LeafBox leaf;
  leaf.box = voxelBox(spec, v);
  leaf.count = count;
  int ix = 0, iy = 0, it = 0;
  spec.unindex(v, ix, iy, it);
  leaf.ix = ix;
  leaf.iy = iy;
  leaf.it = it;
  return leaf;
}

}  // namespace core
}  // namespace fdml_localization
