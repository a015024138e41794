/**
 * @file grid_trace.h
 * @brief Tracing the boundary of a region of grid cells into rings (used by gridToPolygon()).
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/// The offset [cells] of GridWalls::Measured: 1/32 cell short of the wall cells' centres, so
/// that a wall one cell thick keeps 1/16 cell and no ring touches another.
constexpr double kMeasuredWallOffset = 15.0 / 32.0;

/**
 * @brief Traces the boundary of a region of cells, region on the left (the outer boundary
 *        counter-clockwise, holes clockwise), in local cell units: cell (ix, iy) spans
 *        [ix, ix + 1] x [iy, iy + 1].
 *
 * Every side between a region cell and a non-region cell is moved by @p offset cells into the
 * non-region cell (corners mitred). Offset 0 follows the cell edges, so a ray meets the ring
 * where it meets the first non-region cell; offset 1/2 would run through the centres of the
 * boundary wall cells, where a grid made by ray casting puts the measured surface on average
 * (kMeasuredWallOffset stops 1/32 cell short of them). At a vertex where the region touches
 * itself only diagonally (a saddle), the two wall cells meeting there stay joined by a
 * diagonal strip g * sqrt(2) cells wide, g = min(1/8, 1 - 2 offset - 1/32) (at offset 0, a
 * 1/8-cell chamfer off each region corner), and a wall one cell thick keeps 1 - 2 offset: no
 * ring touches itself or another. Every vertex is a multiple of 1/32 cell (exact in binary)
 * when @p offset is.
 *
 * @param region width * height flags, row-major, row 0 at the bottom
 * @param offset [cells] in [0, 15/32], a multiple of 1/32 for exact vertices
 */
std::vector<Ring> traceRegionBoundaries(const std::vector<char>& region, int width, int height, double offset);

}  // namespace core
}  // namespace fdml_localization
