/**
 * @file box_occupancy.h
 * @brief Constant-time conservative box queries against a map for the adaptive search: does a
 *        box possibly touch a map edge, does it possibly contain free space.
 *
 * The map's bounding box is cut into square cells. A cell is an edge cell when some edge may
 * touch it (marked conservatively along each edge); the other cells form 4-connected regions
 * that no edge crosses, so each region is wholly inside or wholly outside free space (one
 * point-in-polygon test per region). Summed-area tables of both classes answer a box query in
 * O(1); "no" answers are exact (never wrong), "maybe" answers are refined by the caller.
 */
#pragma once

#include "fdml_localization/core/geometry/ray_caster.h"

#include <cstdint>
#include <vector>

namespace fdml_localization
{
namespace core
{
class BoxOccupancy
{
public:
  BoxOccupancy() = default;
  /**
   * @param map the map
   * @param cell_size requested cell edge [m]; enlarged so that neither side exceeds
   *        @p max_cells_per_side cells
   * @param max_cells_per_side cap on the grid size (memory is about 8 bytes per cell)
   */
  BoxOccupancy(const MapRayCaster& map, double cell_size, int max_cells_per_side = 4096);

  /// False only when no map edge touches the closed box.
  bool mayTouchEdge(const Box2& box) const;
  /// False only when the whole box lies outside free space (points on edges count as free).
  bool mayBeFree(const Box2& box) const;

  double cellSize() const
  {
    return cell_;
  }
  int cellsX() const
  {
    return nx_;
  }
  int cellsY() const
  {
    return ny_;
  }

private:
  /// Number of marked cells in the clamped cell range covering the box (0 when outside).
  std::int64_t count(const std::vector<std::int32_t>& table, const Box2& box) const;

  /// 1 for every cell an edge may touch (per column strip, the edge's y range there, widened by
  /// a margin that absorbs rounding; @p longest is the bounds' longer side [m]).
  std::vector<std::uint8_t> edgeCells(const MapRayCaster& map, double longest) const;
  /// 1 for edge cells and for the cells of edge-free regions inside free space (one
  /// point-in-polygon test per region).
  std::vector<std::uint8_t> freeOrEdgeCells(const MapRayCaster& map, const std::vector<std::uint8_t>& edge) const;

  /// Cell index along an axis of an offset from the bounds' minimum [m], clamped to [0, cells).
  int cellIndex(double offset, int cells) const;

  Box2 bounds_;
  double cell_ = 1.0;
  double inv_cell_ = 1.0;
  int nx_ = 0;
  int ny_ = 0;
  std::vector<std::int32_t> edge_sum_;  ///< summed-area table of edge cells, (nx+1) x (ny+1)
  std::vector<std::int32_t> free_sum_;  ///< summed-area table of edge-or-free cells
};

}  // namespace core
}  // namespace fdml_localization
