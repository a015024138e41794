/**
 * @file voxel_grid.h
 * @brief The uniform pose grid of the voxel engine (square cells in x, y; periodic theta)
 *        and bit-packed voxel sets over it.
 */
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
/**
 * @brief The one float-to-index conversion of the voxel engine: floor(@p value) when it is a
 *        number with |value| < @p limit (so it fits an int), false otherwise (NaN, inf, huge).
 * @param limit a bound well inside the int range, e.g. a few grid sizes
 */
inline bool floorIndex(double value, double limit, int& index)
{
  if (!(std::abs(value) < limit) || !(limit < 1e9))
  {
    return false;
  }
  index = static_cast<int>(std::floor(value));
  return true;
}

/**
 * @brief Geometry of an nx x ny x nt voxel grid over (x, y, theta).
 *
 * Voxel (ix, iy, it) covers [origin_x + ix c, origin_x + (ix + 1) c) x [..y..] x
 * [-pi + it dt, -pi + (it + 1) dt) with c = cell and dt = 2 pi / nt. The distance table
 * samples h at the voxel centres. Linear index: (it * ny + iy) * nx + ix.
 */
struct GridSpec
{
  double origin_x = 0.0;  ///< x of the grid's lower-left corner [m]
  double origin_y = 0.0;  ///< y of the grid's lower-left corner [m]
  double cell = 1.0;      ///< cell edge in x and y [m]
  int nx = 0;
  int ny = 0;
  int nt = 0;

  /**
   * @brief The grid for a map: @p resolution cells along the bounding box's longer side,
   *        plus one margin cell on every side (so every free pose has a full sample block).
   * @param theta_resolution cells in theta; 0 = resolution
   * @throws std::invalid_argument for a map with no area or a resolution outside [16, 1024]
   */
  static GridSpec fromMap(const PolygonMap& map, int resolution, int theta_resolution);
  /// The same grid over the box @p bounds [m] (e.g. searchBounds()).
  static GridSpec fromBounds(const Box2& bounds, int resolution, int theta_resolution);

  double thetaStep() const;
  std::size_t voxelCount() const
  {
    return static_cast<std::size_t>(nx) * ny * nt;
  }
  std::size_t index(int ix, int iy, int it) const
  {
    return (static_cast<std::size_t>(it) * ny + iy) * nx + ix;
  }
  void unindex(std::size_t v, int& ix, int& iy, int& it) const;
  double centreX(int ix) const
  {
    return origin_x + (ix + 0.5) * cell;
  }
  double centreY(int iy) const
  {
    return origin_y + (iy + 0.5) * cell;
  }
  /// Centre angle of theta cell @p it [rad], in [-pi, pi).
  double centreTheta(int it) const;
  /// The pose at the centre of voxel @p v.
  Pose2 centre(std::size_t v) const;
  /// The voxel holding @p pose (rounded to the nearest cell); false when outside the grid.
  bool locate(const Pose2& pose, int& ix, int& iy, int& it) const;

  /// Stable 64-bit hash of the parameters (for cache keys).
  std::uint64_t hash() const;
  bool operator==(const GridSpec& other) const;
  bool operator!=(const GridSpec& other) const
  {
    return !(*this == other);
  }
};

/**
 * @brief A set of voxels, one bit each. Rows along x are padded to whole 64-bit words, so
 *        row (iy, it) starts at word (it * ny + iy) * wordsPerRow(). Padding bits stay 0.
 */
class VoxelSet
{
public:
  VoxelSet() = default;
  explicit VoxelSet(const GridSpec& spec);

  int wordsPerRow() const
  {
    return words_per_row_;
  }
  bool test(int ix, int iy, int it) const
  {
    return (row(iy, it)[ix >> 6] >> (ix & 63)) & 1u;
  }
  void set(int ix, int iy, int it)
  {
    row(iy, it)[ix >> 6] |= std::uint64_t(1) << (ix & 63);
  }
  std::uint64_t* row(int iy, int it)
  {
    return words_.data() + (static_cast<std::size_t>(it) * ny_ + iy) * words_per_row_;
  }
  const std::uint64_t* row(int iy, int it) const
  {
    return words_.data() + (static_cast<std::size_t>(it) * ny_ + iy) * words_per_row_;
  }
  std::vector<std::uint64_t>& words()
  {
    return words_;
  }
  const std::vector<std::uint64_t>& words() const
  {
    return words_;
  }

  /// Number of voxels in the set.
  std::size_t count() const;
  void clear();
  /// Empties heading slice @p it.
  void clearSlice(int it);
  /// Takes @p spec's shape, keeping this set's storage where it is large enough; the bits are
  /// left as they are (to be written in full, or cleared slice by slice).
  void reshape(const GridSpec& spec);
  /// The set dilated by one voxel in every direction (3 x 3 x 3 box; theta wraps around,
  /// x and y are clipped at the grid's edge).
  VoxelSet dilated() const;
  /// dilated() into @p out (another set), whose storage is reused (no allocation when it has
  /// this shape).
  void dilateInto(VoxelSet& out) const;

  VoxelSet& operator&=(const VoxelSet& other);
  VoxelSet& operator|=(const VoxelSet& other);
  bool operator==(const VoxelSet& other) const;

private:
  int nx_ = 0;
  int ny_ = 0;
  int nt_ = 0;
  int words_per_row_ = 0;
  std::vector<std::uint64_t> words_;
};

}  // namespace core
}  // namespace fdml_localization
