// core::rasterize: a polygon map as an occupancy grid, SLAM-like or as a floor plan.
#include "fdml_localization/core/map/grid/grid_raster.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
PolygonMap roomWithPillar()
{
  return PolygonMap::fromRings({ { Vec2(0, 0), Vec2(2, 0), Vec2(2, 1), Vec2(0, 1) },
                                 { Vec2(0.8, 0.3), Vec2(1.2, 0.3), Vec2(1.2, 0.7), Vec2(0.8, 0.7) } },
                               "grid_room");
}

std::int8_t cellAt(const OccupancyGrid& grid, double x, double y)
{
  const int col = static_cast<int>(std::floor((x - grid.origin.x) / grid.resolution));
  const int row = static_cast<int>(std::floor((y - grid.origin.y) / grid.resolution));
  return grid.at(col, row);
}
}  // namespace

TEST(GridRaster, FloorPlanFillsObstaclesAndKeepsTheOutsideUnknown)
{
  RasterizeOptions options;
  options.resolution = 0.05;
  options.margin = 0.1;
  options.wall_thickness = 0.05;
  const OccupancyGrid slam = rasterize(roomWithPillar(), options);
  options.fill_obstacles = true;
  const OccupancyGrid plan = rasterize(roomWithPillar(), options);
  ASSERT_EQ(plan.cells.size(), static_cast<std::size_t>(plan.width) * plan.height);
  EXPECT_EQ(cellAt(plan, 0.4, 0.5), 0);     // free
  EXPECT_EQ(cellAt(plan, 1.0, 0.5), 100);   // inside the pillar
  EXPECT_EQ(cellAt(slam, 1.0, 0.5), -1);    // a SLAM map never saw it
  EXPECT_EQ(cellAt(slam, 0.81, 0.5), 100);  // the pillar's first cell: its wall in either style
  EXPECT_EQ(cellAt(plan, -0.08, 0.5), -1);  // outside the map
  int free_cells = 0;
  for (std::size_t i = 0; i < plan.cells.size(); ++i)
  {
    free_cells += plan.cells[i] == 0 ? 1 : 0;
    // The two styles differ only inside obstacles, where the floor plan is occupied.
    if (plan.cells[i] != slam.cells[i])
    {
      EXPECT_EQ(plan.cells[i], 100);
      EXPECT_EQ(slam.cells[i], -1);
    }
  }
  // Free area 2 - 0.16 = 1.84 m^2 up to the cells the walls (7.6 m) cut on either side.
  EXPECT_GT(free_cells * 0.05 * 0.05, 1.84 - 7.6 * 0.05);
  EXPECT_LT(free_cells * 0.05 * 0.05, 1.84 + 7.6 * 0.05);
}

TEST(GridRaster, AGridTooLargeForAnIntIsRefusedWithAMessage)
{
  // A 2 x 1 m map at 1e-9 m cells: 2e9 cells a side overflowed an int before.
  RasterizeOptions options;
  options.resolution = 1e-9;
  try
  {
    rasterize(roomWithPillar(), options);
    ADD_FAILURE() << "no error";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("coarser resolution"), std::string::npos) << e.what();
  }
  options.resolution = 0.05;
  options.wall_thickness = 1e300;
  EXPECT_THROW(rasterize(roomWithPillar(), options), std::invalid_argument);
}

}  // namespace core
}  // namespace fdml_localization
