#include "fdml_localization/io/map_files.h"

#include <stb/stb_image_write.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace fdml_localization
{
namespace io
{
using core::OccupancyGrid;
using core::PolygonMap;
using core::Ring;
using core::Vec2;

namespace
{
using Rgb = std::array<std::uint8_t, 3>;

struct Canvas
{
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;

  void set(int x, int y, const Rgb& c)
  {
    if (x < 0 || y < 0 || x >= width || y >= height)
    {
      return;
    }
    std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * width + x) * 3];
    p[0] = c[0];
    p[1] = c[1];
    p[2] = c[2];
  }

  /// A line between two points in pixel units, two pixels thick.
  void line(const Vec2& a, const Vec2& b, const Rgb& c)
  {
    const int steps = std::max(1, static_cast<int>(std::ceil(2.0 * (b - a).norm())));
    for (int s = 0; s <= steps; ++s)
    {
      const Vec2 p = a + (b - a) * (static_cast<double>(s) / steps);
      const int x = static_cast<int>(std::floor(p.x()));
      const int y = static_cast<int>(std::floor(p.y()));
      set(x, y, c);
      set(x + 1, y, c);
      set(x, y + 1, c);
      set(x + 1, y + 1, c);
    }
  }
};

Rgb cellColour(std::int8_t v)
{
  if (v < 0 || v > 100)
  {
    return { 160, 160, 160 };
  }
  const auto g = static_cast<std::uint8_t>(255 - (v * 215) / 100);  // 0 -> white, 100 -> dark
  return { g, g, g };
}
}  // namespace

void writePreviewPng(const std::string& path, const OccupancyGrid& grid, const PolygonMap& map)
{
  const std::vector<std::string> issues = grid.validate();
  if (!issues.empty())
  {
    throw std::invalid_argument("writePreviewPng(" + path + "): invalid grid: " + issues.front());
  }
  const int longest = std::max(grid.width, grid.height);
  const int scale = std::clamp((1200 + longest - 1) / longest, 1, 8);
  Canvas canvas;
  canvas.width = grid.width * scale;
  canvas.height = grid.height * scale;
  canvas.rgb.assign(static_cast<std::size_t>(canvas.width) * canvas.height * 3, 0);
  for (int iy = 0; iy < grid.height; ++iy)
  {
    for (int ix = 0; ix < grid.width; ++ix)
    {
      const Rgb c = cellColour(grid.at(ix, iy));
      for (int dy = 0; dy < scale; ++dy)
      {
        for (int dx = 0; dx < scale; ++dx)
        {
          canvas.set(ix * scale + dx, (grid.height - 1 - iy) * scale + dy, c);
        }
      }
    }
  }
  auto toPixel = [&](const Vec2& p) {
    const Vec2 local = grid.toLocal(p) / grid.resolution * scale;
    return Vec2(local.x() - 0.5, canvas.height - local.y() - 0.5);
  };
  for (std::size_t r = 0; r < map.rings().size(); ++r)
  {
    const Ring& ring = map.rings()[r];
    const Rgb colour = r == 0 ? Rgb{ 0, 90, 255 } : Rgb{ 230, 30, 30 };
    for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
    {
      canvas.line(toPixel(ring[j]), toPixel(ring[i]), colour);
    }
  }
  if (!stbi_write_png(path.c_str(), canvas.width, canvas.height, 3, canvas.rgb.data(), canvas.width * 3))
  {
    throw std::runtime_error(path + ": cannot write the PNG preview");
  }
}

}  // namespace io
}  // namespace fdml_localization
