#include "fdml_localization/ros/map_loading.h"

#include "fdml_localization/ros/param_utils.h"
#include "fdml_localization/io/map_files.h"

#include <cstdio>
#include <filesystem>
#include <fstream>

namespace fdml_localization
{

std::string resolveMapPath(const std::string& location, const std::string& parameter)
{
  std::string error;
  const std::string path = resolveResourcePath(location, &error);
  if (!error.empty())
  {
    throw MapLoadError(parameter + " \"" + location + "\": " + error);
  }
  return path;
}

namespace
{
/// resolveMapPath(), checked to name a readable file.
std::string readablePath(const std::string& location, const std::string& parameter)
{
  const std::string path = resolveMapPath(location, parameter);
  if (!std::ifstream(path).good())
  {
    throw MapLoadError(parameter + " \"" + location + "\": cannot open \"" + path + "\" (missing or unreadable)");
  }
  return path;
}
}  // namespace

std::string describeConversion(const core::OccupancyGrid& grid, const core::GridConversionReport& report)
{
  char text[512];
  std::snprintf(text, sizeof(text),
                "%d x %d cells at %g m; %d free region(s), kept %ld of %ld free cells; holes: %d found, %d under "
                "%g m^2 dropped as specks, %d kept; rings: %d; vertices: %ld traced, %ld kept (tolerance %g m, %d "
                "ring(s) tightened)",
                grid.width, grid.height, grid.resolution, report.regions, report.region_cells, report.free_cells,
                report.holes_found, report.holes_dropped, report.min_area_used,
                report.holes_found - report.holes_dropped, 1 + report.holes_found - report.holes_dropped,
                report.vertices_traced, report.vertices_kept, report.tolerance_used, report.rings_tightened);
  return text;
}

LoadedMap mapFromGrid(const core::OccupancyGrid& grid, const core::GridConversionOptions& options,
                      const std::string& source)
{
  LoadedMap loaded;
  loaded.source = source;
  loaded.grid_resolution = grid.resolution;
  try
  {
    core::GridConversionReport report;
    loaded.map = std::make_shared<const core::MapRayCaster>(core::gridToPolygon(grid, options, source, &report));
    loaded.summary = describeConversion(grid, report);
  }
  catch (const std::exception& error)
  {
    throw MapLoadError(error.what());
  }
  return loaded;
}

LoadedMap loadMapFromFile(const std::string& location, const core::GridConversionOptions& options)
{
  const std::string path = readablePath(location, "~map_file");
  try
  {
    io::MapFile file = io::readMapFile(path, options);
    LoadedMap loaded;
    loaded.source = path;
    loaded.grid_resolution = file.cell_size;
    if (!file.grid.empty())
    {
      loaded.summary = path + ": " + describeConversion(file.grid, file.report);
    }
    loaded.map = std::make_shared<const core::MapRayCaster>(std::move(file.map));
    return loaded;
  }
  catch (const std::exception& error)
  {
    throw MapLoadError(std::string("~map_file: ") + error.what());
  }
}

std::shared_ptr<const core::MapRayCaster> loadSearchRegionFile(const std::string& location,
                                                               const std::vector<double>& seed)
{
  if (location.empty())
  {
    return nullptr;
  }
  const std::string path = readablePath(location, "~search_region");
  const core::Vec2 point = seed.size() == 2 ? core::Vec2(seed[0], seed[1]) : core::Vec2::Zero();
  try
  {
    return io::loadSearchRegion(path, seed.size() == 2 ? &point : nullptr);
  }
  catch (const std::exception& error)
  {
    throw MapLoadError(std::string("~search_region: ") + error.what());
  }
}

std::shared_ptr<const core::MapRayCaster> loadMap(const std::string& location)
{
  return loadMapFromFile(location).map;
}

}  // namespace fdml_localization
