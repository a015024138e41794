#include "fdml_localization/core/map/grid/occupancy_grid.h"

#include "fdml_localization/core/map/polygon_map.h"

#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
Vec2 OccupancyGrid::toMap(const Vec2& local) const
{
  return transformPoint(origin, local);
}

Vec2 OccupancyGrid::toLocal(const Vec2& p) const
{
  const double c = std::cos(origin.theta);
  const double s = std::sin(origin.theta);
  const Vec2 d = p - origin.position();
  return Vec2(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
}

Vec2 OccupancyGrid::cellCentre(int ix, int iy) const
{
  return toMap(Vec2((ix + 0.5) * resolution, (iy + 0.5) * resolution));
}

bool OccupancyGrid::cellOf(const Vec2& p, int* ix, int* iy) const
{
  const Vec2 local = toLocal(p) / resolution;
  const double fx = std::floor(local.x());
  const double fy = std::floor(local.y());
  if (!(fx >= 0.0 && fy >= 0.0 && fx < width && fy < height))
  {
    return false;
  }
  *ix = static_cast<int>(fx);
  *iy = static_cast<int>(fy);
  return true;
}

std::vector<std::string> OccupancyGrid::validate() const
{
  std::vector<std::string> issues;
  if (width <= 0 || height <= 0)
  {
    issues.push_back("width and height must be positive (got " + std::to_string(width) + " x " +
                     std::to_string(height) + ")");
  }
  else if (cells.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
  {
    issues.push_back("cells holds " + std::to_string(cells.size()) + " values, width * height is " +
                     std::to_string(static_cast<long long>(width) * height));
  }
  if (!(std::isfinite(resolution) && resolution > 0.0))
  {
    issues.push_back("resolution must be finite and > 0 [m] (got " + std::to_string(resolution) + ")");
  }
  if (!(std::isfinite(origin.x) && std::isfinite(origin.y) && std::isfinite(origin.theta)))
  {
    issues.push_back("origin must be finite");
  }
  return issues;
}

MapMode parseMapMode(const std::string& text)
{
  if (text == "trinary")
  {
    return MapMode::Trinary;
  }
  if (text == "scale")
  {
    return MapMode::Scale;
  }
  if (text == "raw")
  {
    return MapMode::Raw;
  }
  throw std::invalid_argument("unknown map mode '" + text + "' (allowed: trinary, scale, raw)");
}

const char* toString(MapMode mode)
{
  switch (mode)
  {
    case MapMode::Scale:
      return "scale";
    case MapMode::Raw:
      return "raw";
    case MapMode::Trinary:
    default:
      return "trinary";
  }
}

namespace
{
/// One cell from one pixel (map_server's rules, see pixelsToGrid()).
std::int8_t pixelToCell(const std::uint8_t* p, int channels, const MapYaml& meta)
{
  const bool has_alpha = channels == 2 || channels == 4;
  // As map_server: trinary mode averages the alpha channel in with the colours.
  const int avg_channels = (meta.mode == MapMode::Trinary || !has_alpha) ? channels : channels - 1;
  int sum = 0;
  for (int k = 0; k < avg_channels; ++k)
  {
    sum += p[k];
  }
  double value = static_cast<double>(sum) / avg_channels;
  const int alpha = has_alpha ? p[channels - 1] : 255;
  if (meta.negate)
  {
    value = 255.0 - value;
  }
  if (meta.mode == MapMode::Raw)
  {
    return static_cast<std::int8_t>(static_cast<std::uint8_t>(value));
  }
  const double occ = (255.0 - value) / 255.0;
  if (occ > meta.occupied_thresh)
  {
    return 100;
  }
  if (occ < meta.free_thresh)
  {
    return 0;
  }
  if (meta.mode == MapMode::Trinary || alpha == 0)
  {
    return -1;
  }
  const double ratio = (occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh);
  return static_cast<std::int8_t>(99.0 * ratio);
}
}  // namespace

OccupancyGrid pixelsToGrid(const std::uint8_t* pixels, int width, int height, int channels, const MapYaml& meta)
{
  if (width <= 0 || height <= 0 || channels < 1 || channels > 4 || pixels == nullptr)
  {
    throw std::invalid_argument("pixelsToGrid: need width, height > 0 and 1 to 4 channels");
  }
  OccupancyGrid grid;
  grid.width = width;
  grid.height = height;
  grid.resolution = meta.resolution;
  grid.origin = meta.origin;
  grid.cells.assign(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), -1);
  for (int row = 0; row < height; ++row)
  {
    const int iy = height - 1 - row;  // the first image row is the top of the map
    for (int ix = 0; ix < width; ++ix)
    {
      const std::size_t pixel = static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + ix;
      grid.at(ix, iy) = pixelToCell(pixels + pixel * channels, channels, meta);
    }
  }
  return grid;
}

}  // namespace core
}  // namespace fdml_localization
