/**
 * @file fdml_map_rasterize.cpp
 * @brief Rasterises a `.poly` map into a map_server occupancy grid (YAML + PGM), like a SLAM
 *        map: free inside, walls around, unknown beyond, with optional noise, specks and islands.
 *
 * Usage: fdml_map_rasterize IN.poly OUT.yaml [--resolution M] [--margin M] [--wall M]
 *                           [--noise P] [--specks N] [--islands N] [--seed S]
 *        fdml_map_rasterize --help
 * Exit status: 0 on success (and for --help), 2 on bad arguments or bad input.
 */
#include "in_out_arguments.h"

#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/core/util/text_parsing.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"
#include "fdml_localization/io/map_image.h"

#include <cmath>
#include <functional>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace
{
namespace core = fdml_localization::core;
namespace io = fdml_localization::io;

const char* kUsage = "usage: fdml_map_rasterize IN.poly OUT.yaml [--resolution M] [--margin M] [--wall M]\n"
                     "                          [--noise P] [--specks N] [--islands N] [--seed S]\n"
                     "  --resolution M  cell edge [m] (default 0.05)\n"
                     "  --margin M      unknown border around the map [m] (default 0.5)\n"
                     "  --wall M        wall thickness drawn around free space [m] (default 0.15)\n"
                     "  --noise P       probability a free cell beside a wall turns occupied, 0..1 (default 0)\n"
                     "  --specks N      small occupied blobs in free space (default 0)\n"
                     "  --islands N     small free blobs in the unknown area (default 0)\n"
                     "  --seed S        random seed (default 1)\n"
                     "  --help          print this help and exit\n";

int parseCount(const std::string& text, const std::string& option)
{
  const double v = core::parseNumber(text, option);
  if (v != std::floor(v) || v < 0 || v > 1e9)
  {
    throw std::invalid_argument(option + " must be a non-negative integer");
  }
  return static_cast<int>(v);
}

/// Refuses a grid beyond the map image limits (io::kMaxGridSide, io::kMaxGridCells) before it
/// is allocated: a map of huge coordinates would otherwise exhaust memory.
void checkGridSize(const std::string& input, const core::PolygonMap& map, const core::RasterizeOptions& o)
{
  if (!(o.resolution > 0.0) || !std::isfinite(o.margin))
  {
    return;  // core::rasterize() names the bad option
  }
  const double width = std::ceil((map.bounds().size().x() + 2.0 * o.margin) / o.resolution);
  const double height = std::ceil((map.bounds().size().y() + 2.0 * o.margin) / o.resolution);
  if (!(width <= io::kMaxGridSide && height <= io::kMaxGridSide &&
        width * height <= static_cast<double>(io::kMaxGridCells)))
  {
    std::ostringstream os;
    os << input << ": the grid would be " << width << " x " << height << " cells at " << o.resolution
       << " m, beyond the limit (each side at most " << io::kMaxGridSide << ", at most " << io::kMaxGridCells / 1000000
       << " M cells): use a coarser --resolution";
    throw std::invalid_argument(os.str());
  }
}

struct Arguments
{
  std::string input;
  std::string output;
  core::RasterizeOptions options;
};

/// Applies one option flag; false when @p arg is not one of them.
bool applyFlag(const std::string& arg, const std::function<std::string()>& value, core::RasterizeOptions& options)
{
  if (arg == "--resolution")
  {
    options.resolution = core::parseNumber(value(), arg);
  }
  else if (arg == "--margin")
  {
    options.margin = core::parseNumber(value(), arg);
  }
  else if (arg == "--wall")
  {
    options.wall_thickness = core::parseNumber(value(), arg);
  }
  else if (arg == "--noise")
  {
    options.boundary_noise = core::parseNumber(value(), arg);
  }
  else if (arg == "--specks")
  {
    options.specks = parseCount(value(), arg);
  }
  else if (arg == "--islands")
  {
    options.islands = parseCount(value(), arg);
  }
  else if (arg == "--seed")
  {
    options.seed = static_cast<std::uint64_t>(parseCount(value(), arg));
  }
  else
  {
    return false;
  }
  return true;
}

Arguments parseArguments(int argc, char** argv)
{
  Arguments args;
  fdml_localization::tools::parseInOutArguments(
      argc, argv, kUsage,
      [&args](const std::string& flag, const std::function<std::string()>& value) {
        return applyFlag(flag, value, args.options);
      },
      &args.input, &args.output, "need IN.poly and OUT.yaml");
  return args;
}
}  // namespace

int main(int argc, char** argv)
{
  Arguments args;
  try
  {
    args = parseArguments(argc, argv);
  }
  catch (const std::exception& e)
  {
    std::cerr << "fdml_map_rasterize: " << e.what() << "\n" << kUsage;
    return 2;
  }
  try
  {
    const core::PolygonMap map = core::loadPolyFile(args.input);
    checkGridSize(args.input, map, args.options);
    const core::OccupancyGrid grid = core::rasterize(map, args.options);
    io::saveOccupancyGridYaml(args.output, grid);
    std::cout << args.input << " -> " << args.output << ": " << grid.width << " x " << grid.height << " cells at "
              << grid.resolution << " m\n";
  }
  catch (const std::exception& e)
  {
    std::cerr << "fdml_map_rasterize: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
