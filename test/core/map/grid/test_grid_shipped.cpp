// The seed point's choice of region, the one map loader on both file types, and the shipped
// grids: reproducible from their polygons by the rasteriser, converted back close to the walls.
#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/core/map/grid/grid_raster.h"
#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"

#include "grid_test_maps.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <iostream>
#include <filesystem>
#include <random>
#include <string>

namespace fs = std::filesystem;
namespace core = fdml_localization::core;
namespace io = fdml_localization::io;
using core::Vec2;
using grid_test::officeMap;
using grid_test::uniform;

namespace
{
struct Shipped
{
  const char* name;
  double noise;
  int specks;
  int islands;
  std::uint64_t seed;
};

double perimeter(const core::PolygonMap& map)
{
  double sum = 0.0;
  for (const core::Segment& e : map.edges())
  {
    sum += (e.b - e.a).norm();
  }
  return sum;
}

/// Fractions of 2000 rays from random free poses whose range on @p converted is within one
/// and two cells of the range on @p original.
std::pair<double, double> raysWithinCells(const core::PolygonMap& original, const core::PolygonMap& converted,
                                          double cell, std::uint64_t seed)
{
  const core::MapRayCaster truth(original);
  const core::MapRayCaster conv(converted);
  std::mt19937_64 rng(seed);
  int rays = 0;
  int within_one = 0;
  int within_two = 0;
  while (rays < 2000)
  {
    const Vec2 p(original.bounds().min.x() + uniform(rng) * original.bounds().size().x(),
                 original.bounds().min.y() + uniform(rng) * original.bounds().size().y());
    if (!truth.isFree(p))
    {
      continue;
    }
    const core::Pose2 sensor(p.x(), p.y(), core::kTwoPi * uniform(rng));
    const double error = std::abs(truth.range(sensor) - conv.range(sensor)) / cell;
    ++rays;
    within_one += error <= 1.0;
    within_two += error <= 2.0;
  }
  return { within_one / 2000.0, within_two / 2000.0 };
}
}  // namespace

TEST(GridToPolygon, SeedPointPicksItsOwnRoom)
{
  core::OccupancyGrid g;
  g.width = 30;
  g.height = 10;
  g.resolution = 0.2;
  g.cells.assign(300, 100);
  for (int iy = 1; iy < 9; ++iy)
  {
    for (int ix = 1; ix < 29; ++ix)
    {
      g.at(ix, iy) = (ix == 20) ? 100 : 0;  // a big room (x < 20) and a small one
    }
  }
  core::GridConversionOptions options;
  options.walls = core::GridWalls::CellEdges;
  options.tolerance = 1e-9;
  const double big = core::gridToPolygon(g, options).area();
  options.use_seed = true;
  options.seed_point = Vec2(4.5, 1.0);  // cell (22, 5): the small room
  const double small = core::gridToPolygon(g, options).area();
  EXPECT_NEAR(big, 19 * 8 * 0.04, 1e-9);
  EXPECT_NEAR(small, 8 * 8 * 0.04, 1e-9);
}

TEST(GridToPolygon, LoadMapFileDispatchesOnTheExtension)
{
  const fs::path dir = fs::temp_directory_path() / ("fdml_g2p_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const core::PolygonMap office = officeMap();
  core::savePolyFile((dir / "office.poly").string(), office);
  io::saveOccupancyGridYaml((dir / "office.yaml").string(), core::rasterize(office, {}));
  const core::PolygonMap from_poly = io::loadMapFile((dir / "office.poly").string());
  const core::PolygonMap from_yaml = io::loadMapFile((dir / "office.yaml").string());
  fs::remove_all(dir);
  EXPECT_EQ(from_poly.hash(), office.hash());
  EXPECT_EQ(from_yaml.holeCount(), office.holeCount());
  // Rasterised by cell centres, converted with the walls through the wall cells (the default):
  // the free space gains about 15/32 cell along every wall.
  EXPECT_NEAR(from_yaml.area(), office.area() + 15.0 / 32.0 * 0.05 * perimeter(office), 0.5);
}

TEST(ShippedGrids, AreReproducibleFromTheirPolygonsAndConvertBack)
{
  // The commands in docs/maps_occupancy.md.
  const Shipped maps[] = { { "office", 0.1, 40, 12, 7 }, { "apartment", 0.05, 20, 6, 3 } };
  for (const Shipped& m : maps)
  {
    const std::string base = std::string(FDML_SOURCE_DIR) + "/maps/" + m.name;
    const core::PolygonMap original = core::loadPolyFile(base + ".poly");
    core::RasterizeOptions raster;
    raster.boundary_noise = m.noise;
    raster.specks = m.specks;
    raster.islands = m.islands;
    raster.seed = m.seed;
    const core::OccupancyGrid made = core::rasterize(original, raster);
    const core::OccupancyGrid shipped = io::loadOccupancyGridYaml(base + "_grid.yaml");
    EXPECT_EQ(shipped.width, made.width) << m.name;
    EXPECT_EQ(shipped.height, made.height) << m.name;
    EXPECT_EQ(shipped.cells, made.cells) << m.name;
    EXPECT_NEAR(shipped.origin.x, made.origin.x, 1e-12) << m.name;

    core::GridConversionReport report;
    const core::PolygonMap converted = core::gridToPolygon(shipped, {}, m.name, &report);
    EXPECT_EQ(converted.holeCount(), original.holeCount()) << m.name;
    EXPECT_EQ(report.holes_dropped, m.specks) << m.name;
    EXPECT_EQ(report.regions, 1 + m.islands) << m.name;
    EXPECT_LT(std::abs(converted.area() - original.area()), 0.5 * perimeter(original) * shipped.resolution) << m.name;
    // Ray casts on the converted map against the original polygon (the ground truth).
    const auto [within_one, within_two] = raysWithinCells(original, converted, shipped.resolution, m.seed);
    // Measured: office 89.9 % / 96.4 %, apartment 90.9 % / 97.0 % (wall noise seen at grazing
    // angles; these grids are rasterised by cell centres, so the default conversion puts their
    // walls 15/32 cell beyond the plan's: with the walls on the cell edges, 89.7 / 97.3 and
    // 94.6 / 98.7 %).
    std::cout << m.name << ": " << 100 * within_one << " % within one cell, " << 100 * within_two << " % within two\n";
    EXPECT_GE(within_one, 0.85) << m.name;
    EXPECT_GE(within_two, 0.95) << m.name;
  }
}
