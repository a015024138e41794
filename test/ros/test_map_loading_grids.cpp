// The node's map sources report the grid cell size (a .yaml, or a .poly with a cell-size
// header), which sets the grid tolerances; ~no_return maps onto the core option.
#include "fdml_localization/core/map/grid/grid_tolerances.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/ros/map_loading.h"
#include "fdml_localization/ros/params.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <string>

namespace fdml_localization
{
namespace
{
const std::string kData = std::string(FDML_SOURCE_DIR) + "/test/data/";

TEST(MapLoadingGrids, CellSizeFromAGridOrAPolyHeader)
{
  const LoadedMap plain = loadMapFromFile(kData + "node_test_room.poly");
  EXPECT_EQ(plain.grid_resolution, 0.0);
  EXPECT_TRUE(plain.summary.empty());

  const LoadedMap grid = loadMapFromFile(kData + "node_test_room_grid.yaml");
  EXPECT_GT(grid.grid_resolution, 0.0);
  EXPECT_NE(grid.summary.find("cells at"), std::string::npos) << grid.summary;

  const std::string converted = "/tmp/fdml_node_converted_" + std::to_string(::getpid()) + ".poly";
  core::savePolyFile(converted, grid.map->map(), core::cellSizeHeader(grid.grid_resolution));
  const LoadedMap from_poly = loadMapFromFile(converted);
  std::remove(converted.c_str());
  EXPECT_EQ(from_poly.grid_resolution, grid.grid_resolution);
  EXPECT_TRUE(from_poly.summary.empty());

  Params p;
  p.map_file = "room.poly";
  const Params raised = withGridTolerances(p, from_poly.grid_resolution);
  EXPECT_DOUBLE_EQ(raised.localizer.range_tolerance, std::max(p.localizer.range_tolerance, grid.grid_resolution));
}

TEST(MapLoadingGrids, NoReturnParameterMapsOntoTheCoreOption)
{
  Params p;
  p.map_file = "room.poly";
  EXPECT_EQ(toLocalizerOptions(p).no_return, core::NoReturnPolicy::Constraint);
  p.no_return = "weak";
  EXPECT_TRUE(validate(p).empty());
  EXPECT_EQ(toLocalizerOptions(p).no_return, core::NoReturnPolicy::Weak);
  p.no_return = "drop";
  EXPECT_EQ(toLocalizerOptions(p).no_return, core::NoReturnPolicy::Drop);
  p.no_return = "ignore";
  const std::vector<std::string> errors = validate(p);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("~no_return"), std::string::npos) << errors[0];
  EXPECT_NE(errors[0].find("\"weak\""), std::string::npos) << errors[0];
}
}  // namespace
}  // namespace fdml_localization
