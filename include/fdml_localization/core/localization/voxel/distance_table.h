/**
 * @file distance_table.h
 * @brief The distance table of the voxel engine: h (the map's exact ray-cast distance)
 *        sampled at every voxel centre, plus the min / max of h over every 2 x 2 x 2 block
 *        of samples (in range steps), which turns the preimage's sign-change test into two
 *        comparisons.
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/core/localization/voxel/range_steps.h"
#include "fdml_localization/core/localization/voxel/voxel_grid.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
class DistanceTable
{
public:
  DistanceTable() = default;
  /**
   * @param spec the grid
   * @param values h at every voxel centre [m], indexed like GridSpec::index; NaN where the
   *        centre is not in free space
   * @throws std::invalid_argument when the size does not match the grid
   */
  DistanceTable(const GridSpec& spec, std::vector<float> values);

  /// Samples h by exact ray casting (OpenMP, @p threads threads; 0 = all).
  static DistanceTable build(const MapRayCaster& map, const GridSpec& spec, int threads);

  const GridSpec& spec() const
  {
    return spec_;
  }
  bool empty() const
  {
    return values_.empty();
  }
  const std::vector<float>& values() const
  {
    return values_;
  }
  float at(int ix, int iy, int it) const
  {
    return values_[spec_.index(ix, iy, it)];
  }

  /**
   * @brief Min and max of the valid samples of the block (ix..ix+1, iy..iy+1, it..it+1), theta
   *        periodic, stored at index(ix, iy, it), in steps() (the min rounded down, the max up).
   *        A block with no valid sample (or that runs off the grid in x or y) has min = +inf
   *        and max = -inf (their steps).
   */
  const std::vector<std::uint16_t>& blockMin() const
  {
    return block_min_;
  }
  const std::vector<std::uint16_t>& blockMax() const
  {
    return block_max_;
  }
  /// The steps of the block arrays: about 1 / 65000 of the farthest sample.
  const RangeSteps& steps() const
  {
    return steps_;
  }

  /// Bytes held by the table and its block arrays.
  std::size_t memoryBytes() const;

private:
  void computeBlocks();

  GridSpec spec_;
  std::vector<float> values_;
  RangeSteps steps_;
  std::vector<std::uint16_t> block_min_;
  std::vector<std::uint16_t> block_max_;
};

}  // namespace core
}  // namespace fdml_localization
