#include "fdml_localization/io/map_files.h"

#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/grid/grid_tolerances.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/util/file_checks.h"
#include "fdml_localization/io/map_image.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>

namespace fdml_localization
{
namespace io
{
using core::GridConversionOptions;
using core::GridConversionReport;
using core::gridToPolygon;
using core::loadPolyFile;
using core::MapError;
using core::MapRayCaster;
using core::MapYaml;
using core::OccupancyGrid;
using core::parseMapMode;
using core::pixelsToGrid;
using core::PolygonMap;
using core::Pose2;
using core::readPolyCellSize;
using core::Vec2;

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
    throw MapError(path, 0,
                   "missing key '" + key +
                       "' (map_server YAML needs image, resolution, origin, "
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
  {}
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

namespace
{
YAML::Node loadYamlRoot(const std::string& path)
{
  const std::string problem = core::regularFileProblem(path);
  if (!problem.empty())
  {
    throw MapError(path, 0, "cannot open the map YAML file: " + problem);
  }
  std::ifstream in(path);
  if (!in)
  {
    throw MapError(path, 0, "cannot open the map YAML file");
  }
  YAML::Node root;
  try
  {
    root = YAML::Load(in);
  }
  catch (const YAML::ParserException& e)
  {
    throw MapError(path, e.mark.is_null() ? 0 : e.mark.line + 1, "YAML syntax error: " + e.msg);
  }
  if (!root.IsMap())
  {
    throw MapError(path, 0, "not a map_server YAML file (expected a mapping of keys)");
  }
  return root;
}

void readImageAndGeometry(const YAML::Node& root, const std::string& path, MapYaml& meta)
{
  const YAML::Node image = requireKey(root, "image", path);
  if (!image.IsScalar() || image.Scalar().empty() || image.Scalar().find('\0') != std::string::npos)
  {
    throw MapError(path, lineOf(image), "key 'image' must be a file name");
  }
  meta.image = image.Scalar();
  const std::filesystem::path image_path(meta.image);
  meta.image_path = image_path.is_absolute() ? image_path.string() :
                                               (std::filesystem::path(path).parent_path() / image_path).string();

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
}

void readThresholdsAndMode(const YAML::Node& root, const std::string& path, MapYaml& meta)
{
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
}
}  // namespace

MapYaml loadMapYamlFile(const std::string& path)
{
  const YAML::Node root = loadYamlRoot(path);
  MapYaml meta;
  readImageAndGeometry(root, path, meta);
  readThresholdsAndMode(root, path, meta);
  return meta;
}

OccupancyGrid loadOccupancyGridYaml(const std::string& yaml_path)
{
  const MapYaml meta = loadMapYamlFile(yaml_path);
  ImageInfo info;
  const std::vector<std::uint8_t> pixels = loadImagePixels(meta.image_path, info, yaml_path);
  return pixelsToGrid(pixels.data(), info.width, info.height, info.channels, meta);
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

MapFile readMapFile(const std::string& path, const GridConversionOptions& options)
{
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  MapFile file;
  if (ext == ".poly")
  {
    file.map = loadPolyFile(path);
    file.cell_size = readPolyCellSize(path);
    return file;
  }
  if (ext == ".yaml" || ext == ".yml")
  {
    file.grid = loadOccupancyGridYaml(path);
    file.map = gridToPolygon(file.grid, options, path, &file.report);
    file.cell_size = file.grid.resolution;
    return file;
  }
  throw MapError(path, 0,
                 "unknown map file type '" + ext +
                     "' (allowed: .poly polygon files, .yaml/.yml map_server occupancy grids)");
}

PolygonMap loadMapFile(const std::string& path, const GridConversionOptions& options, GridConversionReport* report)
{
  MapFile file = readMapFile(path, options);
  if (report != nullptr)
  {
    *report = file.report;
  }
  return std::move(file.map);
}

std::shared_ptr<const MapRayCaster> loadSearchRegion(const std::string& path, const Vec2* seed)
{
  GridConversionOptions options;
  if (seed != nullptr)
  {
    options.use_seed = true;
    options.seed_point = *seed;
  }
  return std::make_shared<const MapRayCaster>(loadMapFile(path, options));
}

}  // namespace io
}  // namespace fdml_localization
