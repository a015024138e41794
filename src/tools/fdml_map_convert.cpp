/**
 * @file fdml_map_convert.cpp
 * @brief Converts a map_server occupancy grid (YAML + PGM/PNG) into a `.poly` polygon map,
 *        and writes a PNG preview of the polygon over the grid beside it.
 *
 * Usage: fdml_map_convert MAP.yaml OUT.poly [--tolerance M] [--min-area M2] [--seed-point X,Y]
 *                         [--occupied-threshold N] [--no-preview]
 * Exit status: 0 on success, 2 on bad arguments or bad input (the message names the problem).
 */
#include "in_out_arguments.h"

#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/util/text_parsing.h"
#include "fdml_localization/core/map/grid/grid_tolerances.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"

#include <cmath>
#include <functional>
#include <filesystem>
#include <iostream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace
{
namespace core = fdml_localization::core;
namespace io = fdml_localization::io;

const char* kUsage = "usage: fdml_map_convert MAP.yaml OUT.poly [--tolerance M] [--min-area M2] [--seed-point X,Y]\n"
                     "                        [--occupied-threshold N] [--no-preview]\n"
                     "  --tolerance M            Douglas-Peucker tolerance [m] (default: one cell)\n"
                     "  --min-area M2            drop obstacles smaller than this [m^2] (default: ten cells)\n"
                     "  --seed-point X,Y         keep the free region holding this map point [m] (default: the "
                     "largest)\n"
                     "  --occupied-threshold N   cells with value >= N (1..100) are walls (default 50); unknown is a "
                     "wall\n"
                     "  --no-preview             do not write OUT.png\n"
                     "  --help                   print this help and exit\n";

struct Arguments
{
  std::string input;
  std::string output;
  core::GridConversionOptions options;
  bool preview = true;
};

/// Applies one option flag; false when @p arg is not one of them.
bool applyFlag(const std::string& arg, const std::function<std::string()>& value, Arguments& args)
{
  if (arg == "--tolerance")
  {
    args.options.tolerance = core::parseNumber(value(), arg);
    if (args.options.tolerance <= 0.0)
    {
      throw std::invalid_argument("--tolerance must be > 0 [m]");
    }
  }
  else if (arg == "--min-area")
  {
    args.options.min_area = core::parseNumber(value(), arg);
    if (args.options.min_area < 0.0)
    {
      throw std::invalid_argument("--min-area must be >= 0 [m^2]");
    }
  }
  else if (arg == "--seed-point")
  {
    args.options.use_seed = true;
    core::parsePoint(value(), arg, args.options.seed_point.x(), args.options.seed_point.y());
  }
  else if (arg == "--occupied-threshold")
  {
    const double n = core::parseNumber(value(), arg);
    if (n != std::floor(n) || n < 1 || n > 100)
    {
      throw std::invalid_argument("--occupied-threshold must be an integer in [1, 100]");
    }
    args.options.occupied_threshold = static_cast<int>(n);
  }
  else if (arg == "--no-preview")
  {
    args.preview = false;
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
        return applyFlag(flag, value, args);
      },
      &args.input, &args.output, "need MAP.yaml and OUT.poly");
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
    std::cerr << "fdml_map_convert: " << e.what() << "\n" << kUsage;
    return 2;
  }
  core::OccupancyGrid grid;
  core::PolygonMap map;
  core::GridConversionReport report;
  try
  {
    grid = io::loadOccupancyGridYaml(args.input);
    map = core::gridToPolygon(grid, args.options, args.input, &report);
  }
  catch (const std::exception& e)
  {
    std::cerr << "fdml_map_convert: " << e.what() << "\n";
    return 2;
  }
  std::ostringstream comment;
  comment << core::cellSizeHeader(grid.resolution) << "\n"  // read back for the grid tolerances
          << "converted from " << std::filesystem::path(args.input).filename().string() << " by fdml_map_convert"
          << " (tolerance " << report.tolerance_used << " m, min area " << report.min_area_used << " m^2)";
  const std::string png = std::filesystem::path(args.output).replace_extension(".png").string();
  try
  {
    core::savePolyFile(args.output, map, comment.str());
    if (args.preview)
    {
      io::writePreviewPng(png, grid, map);
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "fdml_map_convert: " << e.what() << "\n";
    return 2;
  }
  std::cout << args.input << ": " << grid.width << " x " << grid.height << " cells at " << grid.resolution << " m; "
            << report.regions << " free region(s), kept " << report.region_cells << " of " << report.free_cells
            << " free cells\n"
            << "  holes: " << report.holes_found << " found, " << report.holes_dropped << " under "
            << report.min_area_used << " m^2 dropped, " << map.holeCount() << " kept\n"
            << "  vertices: " << report.vertices_traced << " traced, " << report.vertices_kept << " kept (tolerance "
            << report.tolerance_used << " m, " << report.rings_tightened << " ring(s) tightened to stay valid)\n"
            << "  free area " << map.area() << " m^2 -> " << args.output << (args.preview ? " and " + png : "") << "\n";
  return 0;
}
