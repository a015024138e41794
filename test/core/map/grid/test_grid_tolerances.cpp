// The one tolerance policy for maps from grids, the .poly cell-size header, and the one map
// loader (readMapFile) reporting the cell size of a grid map or of a .poly converted from one.
#include "fdml_localization/core/map/grid/grid_tolerances.h"
#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
namespace core = fdml_localization::core;
namespace io = fdml_localization::io;

namespace
{
core::PolygonMap room()
{
  return core::PolygonMap::fromRings(
      { { { 0, 0 }, { 4, 0 }, { 4, 3 }, { 0, 3 } }, { { 1, 1 }, { 1.5, 1 }, { 1.5, 1.5 }, { 1, 1.5 } } });
}

struct TempDir
{
  fs::path path = fs::temp_directory_path() / ("fdml_tol_" + std::to_string(::getpid()));
  TempDir()
  {
    fs::create_directories(path);
  }
  ~TempDir()
  {
    fs::remove_all(path);
  }
  std::string file(const std::string& name) const
  {
    return (path / name).string();
  }
};
}  // namespace

TEST(GridTolerances, RaiseOnlyTheTolerancesNotSet)
{
  core::LocalizerOptions defaults;  // 2 cm / 5 cm
  core::LocalizerOptions o = core::withGridTolerances(defaults, 0.05);
  EXPECT_DOUBLE_EQ(o.range_tolerance, 0.05);
  EXPECT_DOUBLE_EQ(o.agreement_tolerance, 0.1);
  o = core::withGridTolerances(defaults, 0.01);  // a fine grid keeps the larger defaults
  EXPECT_DOUBLE_EQ(o.range_tolerance, defaults.range_tolerance);
  EXPECT_DOUBLE_EQ(o.agreement_tolerance, defaults.agreement_tolerance);
  for (double none : { 0.0, -1.0, core::kInf, std::nan("") })
  {
    o = core::withGridTolerances(defaults, none);
    EXPECT_DOUBLE_EQ(o.range_tolerance, defaults.range_tolerance);
    EXPECT_DOUBLE_EQ(o.agreement_tolerance, defaults.agreement_tolerance);
  }
  o = core::withGridTolerances(defaults, 0.1, { true, false });
  EXPECT_DOUBLE_EQ(o.range_tolerance, defaults.range_tolerance);
  EXPECT_DOUBLE_EQ(o.agreement_tolerance, 0.2);
  o = core::withGridTolerances(defaults, 0.1, { false, true });
  EXPECT_DOUBLE_EQ(o.range_tolerance, 0.1);
  EXPECT_DOUBLE_EQ(o.agreement_tolerance, defaults.agreement_tolerance);
}

TEST(GridTolerances, CellSizeHeaderRoundTripsThroughPolyFiles)
{
  const TempDir dir;
  core::savePolyFile(dir.file("a.poly"), room(), core::cellSizeHeader(0.05) + "\nconverted from a.yaml");
  core::savePolyFile(dir.file("b.poly"), room(), "a plain polygon map");
  EXPECT_DOUBLE_EQ(core::readPolyCellSize(dir.file("a.poly")), 0.05);
  EXPECT_DOUBLE_EQ(core::readPolyCellSize(dir.file("b.poly")), 0.0);
  EXPECT_DOUBLE_EQ(core::readPolyCellSize(dir.file("missing.poly")), 0.0);
  const io::MapFile a = io::readMapFile(dir.file("a.poly"));
  EXPECT_DOUBLE_EQ(a.cell_size, 0.05);
  EXPECT_TRUE(a.grid.empty());
  EXPECT_EQ(a.map.hash(), room().hash());
  EXPECT_DOUBLE_EQ(io::readMapFile(dir.file("b.poly")).cell_size, 0.0);
  // A header after the first vertex is not a header.
  std::istringstream late("0 0\n# fdml: cell_size 0.05\n1 0\n1 1\n");
  EXPECT_DOUBLE_EQ(core::readCellSizeHeader(late, "late"), 0.0);
}

TEST(GridTolerances, MalformedHeaderNamesTheFileAndLine)
{
  for (const char* bad : { "# fdml: cell_size\n0 0\n", "# fdml: cell_size -1\n", "#x\n# fdml: cell_size 0.05 m\n",
                           "# fdml: cell_size nan\n" })
  {
    std::istringstream in(bad);
    try
    {
      core::readCellSizeHeader(in, "bad.poly");
      ADD_FAILURE() << bad;
    }
    catch (const core::MapError& e)
    {
      EXPECT_EQ(e.file(), "bad.poly");
      EXPECT_GE(e.line(), 1);
      EXPECT_NE(std::string(e.what()).find("cell size"), std::string::npos) << e.what();
    }
  }
}

TEST(GridTolerances, ReadMapFileReportsTheGridOfAYaml)
{
  const TempDir dir;
  core::RasterizeOptions raster;
  raster.resolution = 0.04;
  io::saveOccupancyGridYaml(dir.file("room.yaml"), core::rasterize(room(), raster));
  const io::MapFile file = io::readMapFile(dir.file("room.yaml"));
  EXPECT_DOUBLE_EQ(file.cell_size, 0.04);
  EXPECT_FALSE(file.grid.empty());
  EXPECT_EQ(file.map.holeCount(), 1u);
  EXPECT_GT(file.report.vertices_traced, 0);
  core::GridConversionReport report;
  EXPECT_EQ(io::loadMapFile(dir.file("room.yaml"), {}, &report).hash(), file.map.hash());
  EXPECT_EQ(report.vertices_kept, file.report.vertices_kept);
}

TEST(GridWallsOption, NamesParseAndBadValuesAreRefused)
{
  EXPECT_EQ(core::parseGridWalls("measured"), core::GridWalls::Measured);
  EXPECT_EQ(core::parseGridWalls(core::toString(core::GridWalls::CellEdges)), core::GridWalls::CellEdges);
  EXPECT_THROW(core::parseGridWalls("centres"), std::invalid_argument);
  core::GridConversionOptions options;
  options.walls = static_cast<core::GridWalls>(5);
  core::RasterizeOptions raster;
  EXPECT_THROW(core::gridToPolygon(core::rasterize(room(), raster), options, "grid"), core::MapError);
}
