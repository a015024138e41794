#include "fdml_localization/core/occupancy_grid.h"

#include "fdml_localization/core/polygon_map.h"

#include <stb/stb_image.h>
#include <yaml-cpp/yaml.h>

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
int lineOf(const YAML::Node& node)
{
  const YAML::Mark mark = node.Mark();
  return mark.is_null() ? 0 : mark.line + 1;
}

YAML::Node requireKey(const YAML::Node& root, const std::string& key, const std::string& path)
{
  const YAML::Node node = root[key];
  if (!node || node.IsNull())
  {
    throw MapError(path, 0, "missing key '" + key + "' (map_server YAML needs image, resolution, origin, "
                            "occupied_thresh, free_thresh and negate)");
  }
  return node;
}

double readNumber(const YAML::Node& node, const std::string& key, const std::string& path)
{
  double value = 0.0;
  try
  {
    value = node.as<double>();
  }
  catch (const YAML::Exception&)
  {
    throw MapError(path, lineOf(node), "key '" + key + "' must be a number");
  }
  if (!std::isfinite(value))
  {
    throw MapError(path, lineOf(node), "key '" + key + "' must be finite");
  }
  return value;
}

bool readFlag(const YAML::Node& node, const std::string& key, const std::string& path)
{
  try
  {
    return node.as<int>() != 0;
  }
  catch (const YAML::Exception&)
  {
  }
  try
  {
    return node.as<bool>();
  }
  catch (const YAML::Exception&)
  {
    throw MapError(path, lineOf(node), "key '" + key + "' must be 0, 1, true or false");
  }
}
}  // namespace

MapYaml loadMapYamlFile(const std::string& path)
{
  YAML::Node root;
  {
    std::ifstream in(path);
    if (!in)
    {
      throw MapError(path, 0, "cannot open the map YAML file");
    }
    try
    {
      root = YAML::Load(in);
    }
    catch (const YAML::ParserException& e)
    {
      throw MapError(path, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML syntax error: " + e.msg);
    }
  }
  if (!root.IsMap())
  {
    throw MapError(path, 0, "not a map_server YAML file (expected a mapping of keys)");
  }
  MapYaml meta;
  const YAML::Node image = requireKey(root, "image", path);
  if (!image.IsScalar() || image.Scalar().empty())
  {
    throw MapError(path, lineOf(image), "key 'image' must be a file name");
  }
  meta.image = image.Scalar();
  const std::filesystem::path image_path(meta.image);
  meta.image_path = image_path.is_absolute()
                        ? image_path.string()
                        : (std::filesystem::path(path).parent_path() / image_path).string();

  const YAML::Node resolution = requireKey(root, "resolution", path);
  meta.resolution = readNumber(resolution, "resolution", path);
  if (meta.resolution <= 0.0)
  {
    throw MapError(path, lineOf(resolution), "key 'resolution' must be > 0 [m/cell]");
  }
  const YAML::Node origin = requireKey(root, "origin", path);
  if (!origin.IsSequence() || origin.size() != 3)
  {
    throw MapError(path, lineOf(origin), "key 'origin' must be a list [x, y, yaw] ([m], [m], [rad])");
  }
  meta.origin = Pose2(readNumber(origin[0], "origin", path), readNumber(origin[1], "origin", path),
                      readNumber(origin[2], "origin", path));

  const YAML::Node occ = requireKey(root, "occupied_thresh", path);
  meta.occupied_thresh = readNumber(occ, "occupied_thresh", path);
  const YAML::Node free = requireKey(root, "free_thresh", path);
  meta.free_thresh = readNumber(free, "free_thresh", path);
  if (meta.occupied_thresh < 0.0 || meta.occupied_thresh > 1.0)
  {
    throw MapError(path, lineOf(occ), "key 'occupied_thresh' must be in [0, 1]");
  }
  if (meta.free_thresh < 0.0 || meta.free_thresh > meta.occupied_thresh)
  {
    throw MapError(path, lineOf(free), "key 'free_thresh' must be in [0, occupied_thresh]");
  }
  meta.negate = readFlag(requireKey(root, "negate", path), "negate", path);

  const YAML::Node mode = root["mode"];
  if (mode && !mode.IsNull())
  {
    try
    {
      meta.mode = parseMapMode(mode.as<std::string>());
    }
    catch (const std::exception& e)
    {
      throw MapError(path, lineOf(mode), std::string("key 'mode': ") + e.what());
    }
  }
  return meta;
}

OccupancyGrid pixelsToGrid(const std::uint8_t* pixels, int width, int height, int channels,
                           const MapYaml& meta)
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

  const bool has_alpha = channels == 2 || channels == 4;
  // As map_server: trinary mode averages the alpha channel in with the colours.
  const int avg_channels = (meta.mode == MapMode::Trinary || !has_alpha) ? channels : channels - 1;
  for (int row = 0; row < height; ++row)
  {
    const int iy = height - 1 - row;  // the first image row is the top of the map
    for (int ix = 0; ix < width; ++ix)
    {
      const std::uint8_t* p =
          pixels + (static_cast<std::size_t>(row) * static_cast<std::size_t>(width) + ix) * channels;
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
      std::int8_t cell = -1;
      if (meta.mode == MapMode::Raw)
      {
        cell = static_cast<std::int8_t>(static_cast<std::uint8_t>(value));
      }
      else
      {
        const double occ = (255.0 - value) / 255.0;
        if (occ > meta.occupied_thresh)
        {
          cell = 100;
        }
        else if (occ < meta.free_thresh)
        {
          cell = 0;
        }
        else if (meta.mode == MapMode::Trinary || alpha == 0)
        {
          cell = -1;
        }
        else
        {
          const double ratio = (occ - meta.free_thresh) / (meta.occupied_thresh - meta.free_thresh);
          cell = static_cast<std::int8_t>(99.0 * ratio);
        }
      }
      grid.at(ix, iy) = cell;
    }
  }
  return grid;
}

OccupancyGrid loadOccupancyGridYaml(const std::string& yaml_path)
{
  const MapYaml meta = loadMapYamlFile(yaml_path);
  if (!std::filesystem::exists(meta.image_path))
  {
    throw MapError(meta.image_path, 0, "image file not found (named by '" + meta.image + "' in " + yaml_path + ")");
  }
  int width = 0;
  int height = 0;
  int channels = 0;
  std::unique_ptr<stbi_uc, void (*)(void*)> pixels(stbi_load(meta.image_path.c_str(), &width, &height, &channels, 0),
                                                  stbi_image_free);
  if (!pixels)
  {
    const char* why = stbi_failure_reason();
    throw MapError(meta.image_path, 0,
                   std::string("cannot decode the image (") + (why ? why : "unknown reason") +
                       "; readable: binary PGM, PNG, BMP, JPEG, TGA, GIF), named by " + yaml_path);
  }
  return pixelsToGrid(pixels.get(), width, height, channels, meta);
}

namespace
{
/// The shortest text that reads back as the same double.
std::string shortest(double value)
{
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

std::uint8_t pgmValue(std::int8_t cell)
{
  if (cell == 0)
  {
    return 254;
  }
  if (cell >= 65)
  {
    return 0;
  }
  return 205;
}
}  // namespace

void writePgm(const std::string& path, const OccupancyGrid& grid)
{
  const std::vector<std::string> issues = grid.validate();
  if (!issues.empty())
  {
    throw std::invalid_argument("writePgm(" + path + "): invalid grid: " + issues.front());
  }
  std::ofstream out(path, std::ios::binary);
  if (!out)
  {
    throw std::runtime_error(path + ": cannot open for writing");
  }
  out << "P5\n# fdml_localization occupancy grid, " << grid.resolution << " m/pix\n"
      << grid.width << " " << grid.height << "\n255\n";
  std::vector<char> row(static_cast<std::size_t>(grid.width));
  for (int iy = grid.height - 1; iy >= 0; --iy)
  {
    for (int ix = 0; ix < grid.width; ++ix)
    {
      row[ix] = static_cast<char>(pgmValue(grid.at(ix, iy)));
    }
    out.write(row.data(), static_cast<std::streamsize>(row.size()));
  }
  if (!out)
  {
    throw std::runtime_error(path + ": write failed");
  }
}

void saveOccupancyGridYaml(const std::string& yaml_path, const OccupancyGrid& grid)
{
  const std::filesystem::path yaml(yaml_path);
  const std::filesystem::path pgm = std::filesystem::path(yaml).replace_extension(".pgm");
  writePgm(pgm.string(), grid);
  std::ofstream out(yaml_path);
  if (!out)
  {
    throw std::runtime_error(yaml_path + ": cannot open for writing");
  }
  out << "image: " << pgm.filename().string() << "\n"
      << "resolution: " << shortest(grid.resolution) << "\n"
      << "origin: [" << shortest(grid.origin.x) << ", " << shortest(grid.origin.y) << ", "
      << shortest(grid.origin.theta) << "]\n"
      << "negate: 0\n"
      << "occupied_thresh: 0.65\n"
      << "free_thresh: 0.196\n";
  if (!out)
  {
    throw std::runtime_error(yaml_path + ": write failed");
  }
}

}  // namespace core
}  // namespace fdml_localization
