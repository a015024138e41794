// Occupancy grids: map_server YAML semantics, image loading, writing, and bad input.
#include "fdml_localization/core/map/grid/grid_to_polygon.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/map/grid/occupancy_grid.h"
#include "fdml_localization/io/map_files.h"

#include <gtest/gtest.h>
#include <stb/stb_image_write.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
namespace core = fdml_localization::core;
namespace io = fdml_localization::io;

namespace
{
/// A fresh folder per test, removed afterwards.
class TempDir
{
public:
  TempDir()
  {
    static int counter = 0;
    path_ = fs::temp_directory_path() / ("fdml_occ_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::create_directories(path_);
  }
  ~TempDir()
  {
    fs::remove_all(path_);
  }
  std::string file(const std::string& name) const
  {
    return (path_ / name).string();
  }
  void write(const std::string& name, const std::string& text) const
  {
    std::ofstream out(file(name), std::ios::binary);
    out << text;
  }

private:
  fs::path path_;
};

core::MapYaml meta(core::MapMode mode, bool negate = false)
{
  core::MapYaml m;
  m.mode = mode;
  m.negate = negate;
  return m;
}

/// One grey pixel through map_server's rules.
int greyCell(int value, const core::MapYaml& m)
{
  const std::uint8_t pixel = static_cast<std::uint8_t>(value);
  return core::pixelsToGrid(&pixel, 1, 1, 1, m).cells[0];
}

/// The map_server rule written out directly: p = (255 - v) / 255 after negate.
int expectedTrinary(int v, double occ_th, double free_th)
{
  const double p = (255.0 - v) / 255.0;
  return p > occ_th ? 100 : (p < free_th ? 0 : -1);
}

const char* kValidYaml = "image: map.pgm\nresolution: 0.1\norigin: [1.5, -2.0, 0.25]\nnegate: 0\n"
                         "occupied_thresh: 0.65\nfree_thresh: 0.196\n";
}  // namespace

TEST(MapServerSemantics, TrinaryThresholdsEveryGreyValue)
{
  const core::MapYaml m = meta(core::MapMode::Trinary);
  for (int v = 0; v <= 255; ++v)
  {
    EXPECT_EQ(greyCell(v, m), expectedTrinary(v, 0.65, 0.196)) << "grey " << v;
  }
  // The values map_saver writes.
  EXPECT_EQ(greyCell(0, m), 100);
  EXPECT_EQ(greyCell(254, m), 0);
  EXPECT_EQ(greyCell(205, m), -1);
  // Just either side of the thresholds: p(89) = 0.651 > 0.65, p(90) = 0.647.
  EXPECT_EQ(greyCell(89, m), 100);
  EXPECT_EQ(greyCell(90, m), -1);
  EXPECT_EQ(greyCell(206, m), 0);
}

TEST(MapServerSemantics, NegateSwapsBlackAndWhite)
{
  const core::MapYaml m = meta(core::MapMode::Trinary, true);
  EXPECT_EQ(greyCell(0, m), 0);
  EXPECT_EQ(greyCell(255, m), 100);
  for (int v = 0; v <= 255; ++v)
  {
    EXPECT_EQ(greyCell(v, m), expectedTrinary(255 - v, 0.65, 0.196)) << "grey " << v;
  }
}

TEST(MapServerSemantics, ScaleInterpolatesBetweenThresholds)
{
  const core::MapYaml m = meta(core::MapMode::Scale);
  EXPECT_EQ(greyCell(0, m), 100);
  EXPECT_EQ(greyCell(254, m), 0);
  // v = 150: p = 105 / 255, 99 * (p - 0.196) / (0.65 - 0.196) = 47.05 -> 47.
  EXPECT_EQ(greyCell(150, m), 47);
  // v = 205: p = 0.19608, just above free_thresh -> 99 * 0.00017 -> 0.
  EXPECT_EQ(greyCell(205, m), 0);
  // Grey + alpha: alpha 0 makes an in-between value unknown, opaque keeps it scaled.
  const std::uint8_t transparent[2] = { 150, 0 };
  const std::uint8_t opaque[2] = { 150, 255 };
  EXPECT_EQ(core::pixelsToGrid(transparent, 1, 1, 2, m).cells[0], -1);
  EXPECT_EQ(core::pixelsToGrid(opaque, 1, 1, 2, m).cells[0], 47);
}

TEST(MapServerSemantics, TrinaryAveragesAlphaLikeMapServer)
{
  // RGBA (0, 0, 0, 255): trinary averages all four channels -> 63.75 -> p = 0.75 -> occupied.
  // Scale ignores alpha: mean 0 -> occupied as well; (120, 120, 120, 255): trinary mean 153.75
  // (p = 0.397 -> unknown), scale mean 120 (p = 0.529 -> 99 * 0.733 = 72).
  const std::uint8_t black[4] = { 0, 0, 0, 255 };
  const std::uint8_t grey[4] = { 120, 120, 120, 255 };
  EXPECT_EQ(core::pixelsToGrid(black, 1, 1, 4, meta(core::MapMode::Trinary)).cells[0], 100);
  EXPECT_EQ(core::pixelsToGrid(grey, 1, 1, 4, meta(core::MapMode::Trinary)).cells[0], -1);
  EXPECT_EQ(core::pixelsToGrid(grey, 1, 1, 4, meta(core::MapMode::Scale)).cells[0], 72);
}

TEST(MapServerSemantics, RawCopiesValuesAsSignedBytes)
{
  const core::MapYaml m = meta(core::MapMode::Raw);
  EXPECT_EQ(greyCell(0, m), 0);
  EXPECT_EQ(greyCell(100, m), 100);
  EXPECT_EQ(greyCell(255, m), -1);
  EXPECT_EQ(greyCell(155, meta(core::MapMode::Raw, true)), 100);
}

TEST(MapServerSemantics, FirstImageRowIsTheTopOfTheMap)
{
  // 2 x 3 image, rows top to bottom: black black / white white / grey grey.
  const std::uint8_t pixels[6] = { 0, 0, 254, 254, 205, 205 };
  const core::OccupancyGrid g = core::pixelsToGrid(pixels, 2, 3, 1, meta(core::MapMode::Trinary));
  ASSERT_EQ(g.width, 2);
  ASSERT_EQ(g.height, 3);
  EXPECT_EQ(g.at(0, 2), 100);
  EXPECT_EQ(g.at(1, 1), 0);
  EXPECT_EQ(g.at(0, 0), -1);
}

TEST(MapYaml, ParsesEveryKeyAndResolvesTheImageBesideTheYaml)
{
  TempDir dir;
  dir.write("a.yaml", std::string(kValidYaml) + "mode: scale\n");
  const core::MapYaml m = io::loadMapYamlFile(dir.file("a.yaml"));
  EXPECT_EQ(m.image, "map.pgm");
  EXPECT_EQ(fs::path(m.image_path), fs::path(dir.file("map.pgm")));
  EXPECT_DOUBLE_EQ(m.resolution, 0.1);
  EXPECT_DOUBLE_EQ(m.origin.x, 1.5);
  EXPECT_DOUBLE_EQ(m.origin.y, -2.0);
  EXPECT_DOUBLE_EQ(m.origin.theta, 0.25);
  EXPECT_DOUBLE_EQ(m.occupied_thresh, 0.65);
  EXPECT_DOUBLE_EQ(m.free_thresh, 0.196);
  EXPECT_FALSE(m.negate);
  EXPECT_EQ(m.mode, core::MapMode::Scale);

  dir.write("b.yaml", "image: /abs/x.png\nresolution: 1\norigin: [0, 0, 0]\nnegate: true\n"
                      "occupied_thresh: 0.9\nfree_thresh: 0.1\n");
  const core::MapYaml b = io::loadMapYamlFile(dir.file("b.yaml"));
  EXPECT_EQ(b.image_path, "/abs/x.png");
  EXPECT_TRUE(b.negate);
  EXPECT_EQ(b.mode, core::MapMode::Trinary);
}

TEST(MapYaml, SaveAndLoadRoundTripThroughPgm)
{
  TempDir dir;
  core::OccupancyGrid g;
  g.width = 7;
  g.height = 5;
  g.resolution = 0.05;
  g.origin = core::Pose2(-1.25, 3.5, 0.5);
  for (int i = 0; i < g.width * g.height; ++i)
  {
    g.cells.push_back(static_cast<std::int8_t>(i % 3 == 0 ? 0 : (i % 3 == 1 ? 100 : -1)));
  }
  io::saveOccupancyGridYaml(dir.file("g.yaml"), g);
  ASSERT_TRUE(fs::exists(dir.file("g.pgm")));
  const core::OccupancyGrid back = io::loadOccupancyGridYaml(dir.file("g.yaml"));
  EXPECT_EQ(back.width, g.width);
  EXPECT_EQ(back.height, g.height);
  EXPECT_DOUBLE_EQ(back.resolution, g.resolution);
  EXPECT_DOUBLE_EQ(back.origin.x, g.origin.x);
  EXPECT_DOUBLE_EQ(back.origin.y, g.origin.y);
  EXPECT_DOUBLE_EQ(back.origin.theta, g.origin.theta);
  EXPECT_EQ(back.cells, g.cells);
}

TEST(MapYaml, LoadsPngWithNegate)
{
  TempDir dir;
  // 3 x 1 RGB PNG: black, white, mid grey. Negated: black free, white occupied.
  const std::uint8_t rgb[9] = { 0, 0, 0, 255, 255, 255, 128, 128, 128 };
  ASSERT_TRUE(stbi_write_png(dir.file("m.png").c_str(), 3, 1, 3, rgb, 9));
  dir.write("m.yaml", "image: m.png\nresolution: 0.2\norigin: [0, 0, 0]\nnegate: 1\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  const core::OccupancyGrid g = io::loadOccupancyGridYaml(dir.file("m.yaml"));
  ASSERT_EQ(g.width, 3);
  EXPECT_EQ(g.at(0, 0), 0);
  EXPECT_EQ(g.at(1, 0), 100);
  EXPECT_EQ(g.at(2, 0), -1);
}

TEST(GridGeometry, CellCentresFollowTheOriginPose)
{
  core::OccupancyGrid g;
  g.width = 4;
  g.height = 3;
  g.resolution = 0.5;
  g.origin = core::Pose2(10.0, 20.0, core::kPi / 2);
  g.cells.assign(12, 0);
  // Local (x, y) -> map (10 - y, 20 + x) under a quarter turn.
  const core::Vec2 c = g.cellCentre(1, 2);
  EXPECT_NEAR(c.x(), 10.0 - 1.25, 1e-12);
  EXPECT_NEAR(c.y(), 20.0 + 0.75, 1e-12);
  int ix = -1;
  int iy = -1;
  ASSERT_TRUE(g.cellOf(c, &ix, &iy));
  EXPECT_EQ(ix, 1);
  EXPECT_EQ(iy, 2);
  EXPECT_FALSE(g.cellOf(core::Vec2(10.5, 20.0), &ix, &iy));  // behind the origin
}

// ---------------------------------------------------------------------------
// Bad input: every error names the file and the problem.
// ---------------------------------------------------------------------------

namespace
{
/// Runs @p fn, expecting a MapError whose message holds every fragment.
template <typename Fn>
void expectMapError(Fn fn, const std::vector<std::string>& fragments)
{
  try
  {
    fn();
    ADD_FAILURE() << "no MapError thrown";
  }
  catch (const core::MapError& e)
  {
    const std::string what = e.what();
    for (const std::string& f : fragments)
    {
      EXPECT_NE(what.find(f), std::string::npos) << "'" << f << "' missing from: " << what;
    }
  }
}
}  // namespace

TEST(BadGridInput, MissingImageNamesTheImageAndTheYaml)
{
  TempDir dir;
  dir.write("a.yaml", kValidYaml);
  expectMapError([&] { io::loadOccupancyGridYaml(dir.file("a.yaml")); },
                 { dir.file("map.pgm"), "not found", "a.yaml" });
}

TEST(BadGridInput, UnreadableImageNamesTheImage)
{
  TempDir dir;
  dir.write("a.yaml", kValidYaml);
  dir.write("map.pgm", "this is not an image at all");
  expectMapError([&] { io::loadOccupancyGridYaml(dir.file("a.yaml")); }, { dir.file("map.pgm"), "cannot decode" });
}

TEST(BadGridInput, MissingYamlFile)
{
  TempDir dir;
  expectMapError([&] { io::loadOccupancyGridYaml(dir.file("none.yaml")); }, { "none.yaml", "cannot open" });
}

TEST(BadGridInput, EachMissingKeyIsNamed)
{
  TempDir dir;
  const std::vector<std::string> keys = { "image", "resolution", "origin", "negate", "occupied_thresh", "free_thresh" };
  for (const std::string& key : keys)
  {
    std::string text;
    std::istringstream lines(kValidYaml);
    for (std::string line; std::getline(lines, line);)
    {
      if (line.rfind(key + ":", 0) != 0)
      {
        text += line + "\n";
      }
    }
    dir.write(key + ".yaml", text);
    expectMapError([&] { io::loadMapYamlFile(dir.file(key + ".yaml")); },
                   { key + ".yaml", "missing key '" + key + "'" });
  }
}

TEST(BadGridInput, BadValuesNameTheKeyAndLine)
{
  TempDir dir;
  dir.write("r.yaml", "image: m.pgm\nresolution: -0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  expectMapError([&] { io::loadMapYamlFile(dir.file("r.yaml")); }, { "r.yaml:2", "resolution", "> 0" });
  dir.write("o.yaml", "image: m.pgm\nresolution: 0.05\norigin: [0, 0]\nnegate: 0\n"
                      "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  expectMapError([&] { io::loadMapYamlFile(dir.file("o.yaml")); }, { "o.yaml:3", "origin", "[x, y, yaw]" });
  dir.write("m.yaml", std::string(kValidYaml) + "mode: fancy\n");
  expectMapError([&] { io::loadMapYamlFile(dir.file("m.yaml")); }, { "m.yaml:7", "mode", "trinary, scale, raw" });
  dir.write("t.yaml", "image: m.pgm\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                      "occupied_thresh: 0.2\nfree_thresh: 0.6\n");
  expectMapError([&] { io::loadMapYamlFile(dir.file("t.yaml")); }, { "t.yaml:6", "free_thresh" });
  dir.write("s.yaml", "image: [unclosed\nresolution: 0.05\n");
  expectMapError([&] { io::loadMapYamlFile(dir.file("s.yaml")); }, { "s.yaml", "YAML syntax error" });
  dir.write("n.yaml", "just a sentence\n");
  expectMapError([&] { io::loadMapYamlFile(dir.file("n.yaml")); }, { "n.yaml", "not a map_server YAML" });
}

TEST(BadGridInput, AllOccupiedMapHasNoFreeSpace)
{
  TempDir dir;
  core::OccupancyGrid g;
  g.width = 20;
  g.height = 10;
  g.cells.assign(200, 100);
  g.cells[5] = -1;
  io::saveOccupancyGridYaml(dir.file("walls.yaml"), g);
  expectMapError([&] { io::loadMapFile(dir.file("walls.yaml")); }, { "walls.yaml", "no free cell" });
}

TEST(BadGridInput, SeedPointOutsideOrInAWall)
{
  core::OccupancyGrid g;
  g.width = 10;
  g.height = 10;
  g.resolution = 0.1;
  g.cells.assign(100, 0);
  g.at(3, 3) = 100;
  core::GridConversionOptions options;
  options.use_seed = true;
  options.seed_point = core::Vec2(5.0, 5.0);
  expectMapError([&] { core::gridToPolygon(g, options, "topic /map"); }, { "topic /map", "outside the grid" });
  options.seed_point = core::Vec2(0.35, 0.35);
  expectMapError([&] { core::gridToPolygon(g, options, "topic /map"); }, { "occupied cell (3, 3)" });
  options.use_seed = false;
  options.occupied_threshold = 0;
  expectMapError([&] { core::gridToPolygon(g, options, "topic /map"); }, { "occupied_threshold", "[1, 100]" });
  core::OccupancyGrid broken = g;
  broken.cells.pop_back();
  expectMapError([&] { core::gridToPolygon(broken, {}, "topic /map"); }, { "topic /map", "cells holds 99" });
}

TEST(BadGridInput, UnknownMapExtension)
{
  expectMapError([] { io::loadMapFile("maps/office.png"); }, { "office.png", "unknown map file type" });
}
