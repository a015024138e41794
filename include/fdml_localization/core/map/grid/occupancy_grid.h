/**
 * @file occupancy_grid.h
 * @brief Occupancy grids as ROS users have them (map_server YAML + PGM/PNG, or a
 *        nav_msgs/OccupancyGrid copied field by field), without any ROS dependency.
 *
 * Cell values follow nav_msgs/OccupancyGrid: -1 unknown, 0 free ... 100 occupied. Cells are
 * stored row-major with row 0 at the bottom (smallest local y), exactly like the message's
 * `data` array, so a node can copy `msg.data` into OccupancyGrid::cells unchanged.
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <cstdint>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A 2-D occupancy grid (the ROS-free twin of nav_msgs/OccupancyGrid).
struct OccupancyGrid
{
  int width = 0;             ///< cells along the grid's local x axis
  int height = 0;            ///< cells along the grid's local y axis
  double resolution = 0.05;  ///< edge of a cell [m]
  /// Pose of the lower-left corner of cell (0, 0) in the map frame ([m], [rad]); the grid's
  /// local x axis points along origin.theta.
  Pose2 origin;
  /// width * height values, row-major, row 0 at the bottom: -1 unknown, 0..100 occupancy [%].
  std::vector<std::int8_t> cells;

  bool empty() const
  {
    return width <= 0 || height <= 0;
  }
  bool inside(int ix, int iy) const
  {
    return ix >= 0 && iy >= 0 && ix < width && iy < height;
  }
  std::size_t index(int ix, int iy) const
  {
    return static_cast<std::size_t>(iy) * static_cast<std::size_t>(width) + static_cast<std::size_t>(ix);
  }
  std::int8_t at(int ix, int iy) const
  {
    return cells[index(ix, iy)];
  }
  std::int8_t& at(int ix, int iy)
  {
    return cells[index(ix, iy)];
  }

  /// Centre of cell (ix, iy) in the map frame [m].
  Vec2 cellCentre(int ix, int iy) const;
  /// A map-frame point [m] in the grid's local frame (cell (0, 0) spans [0, res)^2) [m].
  Vec2 toLocal(const Vec2& p) const;
  /// A point of the grid's local frame [m] in the map frame [m].
  Vec2 toMap(const Vec2& local) const;
  /// The cell holding map-frame point @p p; false when it lies outside the grid.
  bool cellOf(const Vec2& p, int* ix, int* iy) const;

  /// Every problem with the fields (sizes, resolution, finiteness), each naming the field.
  std::vector<std::string> validate() const;
};

/// How map_server turns pixels into occupancy values (its `mode` key).
enum class MapMode
{
  Trinary,  ///< free 0, occupied 100, anything between: unknown -1 (the default)
  Scale,    ///< free 0, occupied 100, between: 99 (p - free) / (occ - free), unknown where alpha is 0
  Raw       ///< the grey value itself (after negate) is the cell value
};

/// Parses "trinary" / "scale" / "raw"; throws std::invalid_argument otherwise.
MapMode parseMapMode(const std::string& text);
const char* toString(MapMode mode);

/// The contents of a map_server YAML file.
struct MapYaml
{
  std::string image;              ///< image path as written in the file
  std::string image_path;         ///< the image path resolved against the YAML's folder
  double resolution = 0.05;       ///< [m / cell], > 0
  Pose2 origin;                   ///< pose of the lower-left pixel's corner ([m], [rad])
  double occupied_thresh = 0.65;  ///< p > this: occupied, in [0, 1]
  double free_thresh = 0.196;     ///< p < this: free, in [0, 1]
  bool negate = false;            ///< true: white is occupied, black is free
  MapMode mode = MapMode::Trinary;
};

/**
 * @brief Converts decoded pixels to cells with map_server's semantics: the mean of the
 *        colour channels (alpha excluded unless trinary), negated when asked, gives
 *        p = (255 - value) / 255; p > occupied_thresh -> 100, p < free_thresh -> 0, else
 *        -1 (trinary, or alpha 0 in scale) or 99 (p - free) / (occ - free) (scale);
 *        raw copies the value (as a signed byte, so 255 becomes -1). The first image row is
 *        the top of the map (the grid's last row).
 * @param pixels width * height * channels bytes, rows from the top of the image
 * @param channels 1 (grey), 2 (grey + alpha), 3 (RGB) or 4 (RGBA)
 */
OccupancyGrid pixelsToGrid(const std::uint8_t* pixels, int width, int height, int channels, const MapYaml& meta);

}  // namespace core
}  // namespace fdml_localization
