/**
 * @file cell_bounds.h
 * @brief Conservative bounds of the ray distance h over every cell of the distance table's
 *        sample lattice, position and heading extent included, depth discontinuities included
 *        (the voxel engine's preimage test; the proof is in docs/METHOD.md).
 *
 * Cell (jx, jy, jt) is every sensor pose whose position lies in the box spanned by the samples
 * (jx, jy) and (jx + 1, jy + 1) and whose heading lies between the sample headings jt and jt + 1.
 * Its free part is cut into convex pieces; for each piece the rays of its vertices at both
 * headings are cast, their hits grouped into connected runs of map edges, and (when the runs
 * are ahead of the piece and their lateral extents overlap) every ray of the piece provably
 * crosses a run: hi is the farthest run point, lo the nearest front-facing edge point in the
 * convex hull of the piece and the runs. Otherwise the cell gets [0, +inf].
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A closed interval of distances [m]; empty when lo > hi.
struct DistanceInterval
{
  double lo = kInf;
  double hi = -kInf;
};

/// @p value rounded to a float not above it (bounds are stored rounded outward).
inline float roundDown(double value)
{
  const float f = static_cast<float>(value);
  return static_cast<double>(f) > value ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

/// @p value rounded to a float not below it.
inline float roundUp(double value)
{
  const float f = static_cast<float>(value);
  return static_cast<double>(f) < value ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

/// Ring topology of a map's edges (MapRayCaster's segment order: ring by ring, vertex order).
struct EdgeRings
{
  explicit EdgeRings(const PolygonMap& map);
  std::vector<int> ring;   ///< ring of each edge
  std::vector<int> start;  ///< first edge of each ring
  std::vector<int> size;   ///< edges of each ring
};

/**
 * @brief Bounds of h over {(p, phi) : p in the convex polygon @p piece, phi in [t0, t1]},
 *        0 < t1 - t0 < pi/2, from the first hits of the rays of the piece's vertices.
 * @param u0 (cos t0, sin t0), the direction the hits at t0 were cast in
 * @param u1 (cos t1, sin t1)
 * @param hits segment hit by the ray of vertex i at heading t0 (index 2 i) and t1 (2 i + 1),
 *        -1 for a miss
 * @return [lo, hi] with lo <= h <= hi for every pose of the piece in free space, or [0, +inf]
 *         when the argument does not apply
 */
DistanceInterval pieceBound(const MapRayCaster& map, const EdgeRings& rings, const std::vector<Vec2>& piece,
                            const Vec2& u0, const Vec2& u1, const std::vector<int>& hits);

/**
 * @brief The free part of the position box as convex pieces, shrunk by @p margin from the
 *        walls: the box, or its quarters (recursively, three times at most), each with no edge,
 *        one edge, or two edges meeting at a vertex; false when that does not suffice.
 */
bool freePieces(const MapRayCaster& map, const Box2& box, double margin, std::vector<std::vector<Vec2>>& pieces);

/**
 * @brief Per-cell bounds of h, float, rounded outward. Stored with one padding cell on each
 *        side in x and y (empty there): cell (jx, jy, jt), jx in [-1, nx - 1], jy in [-1, ny - 1].
 */
class CellBounds
{
public:
  CellBounds() = default;
  /// Casts every sample ray again (for the hit edges) and bounds every cell (OpenMP).
  static CellBounds compute(const MapRayCaster& map, const GridSpec& spec, int threads);

  const GridSpec& spec() const
  {
    return spec_;
  }
  bool empty() const
  {
    return lower_.empty();
  }
  int paddedNx() const
  {
    return spec_.nx + 1;
  }
  int paddedNy() const
  {
    return spec_.ny + 1;
  }
  std::size_t index(int jx, int jy, int jt) const
  {
    return (static_cast<std::size_t>(jt) * paddedNy() + (jy + 1)) * paddedNx() + (jx + 1);
  }
  const std::vector<float>& lower() const
  {
    return lower_;
  }
  const std::vector<float>& upper() const
  {
    return upper_;
  }
  /// Cells whose bound fell back to [0, +inf] (statistics).
  std::size_t fallbackCells() const
  {
    return fallback_cells_;
  }
  std::size_t memoryBytes() const
  {
    return (lower_.capacity() + upper_.capacity()) * sizeof(float);
  }

private:
  GridSpec spec_;
  std::vector<float> lower_;
  std::vector<float> upper_;
  std::size_t fallback_cells_ = 0;
};

}  // namespace core
}  // namespace fdml_localization
