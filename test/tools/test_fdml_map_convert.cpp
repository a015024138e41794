// The fdml_map_convert and fdml_map_rasterize tools: outputs, exit codes and error messages.
#include "fdml_localization/core/map/map_io.h"

#include "temp_dir_test.h"

#include <gtest/gtest.h>
#include <stb/stb_image.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace fs = std::filesystem;
namespace core = fdml_localization::core;

namespace
{
class MapToolsCli : public fdml_localization::test::TempDirTest
{
protected:
  /// Runs a tool; returns its exit code and fills @p out and @p err.
  int run(const std::string& exe, const std::string& args, std::string* out, std::string* err)
  {
    const std::string command = exe + " " + args + " > " + file("out.txt") + " 2> " + file("err.txt");
    const int status = std::system(command.c_str());
    std::stringstream o;
    o << std::ifstream(file("out.txt")).rdbuf();
    std::stringstream e;
    e << std::ifstream(file("err.txt")).rdbuf();
    *out = o.str();
    *err = e.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }
};

const std::string kMaps = std::string(FDML_SOURCE_DIR) + "/maps/";

std::string slurp(const std::string& path)
{
  std::stringstream s;
  s << std::ifstream(path, std::ios::binary).rdbuf();
  return s.str();
}
}  // namespace

TEST_F(MapToolsCli, ConvertWritesAValidPolygonAndAPreview)
{
  std::string out;
  std::string err;
  ASSERT_EQ(run(FDML_MAP_CONVERT_EXE, kMaps + "office_grid.yaml " + file("office.poly"), &out, &err), 0) << err;
  EXPECT_NE(out.find("7 kept"), std::string::npos) << out;
  const core::PolygonMap map = core::loadPolyFile(file("office.poly"));
  EXPECT_EQ(map.holeCount(), core::loadPolyFile(kMaps + "office.poly").holeCount());
  int width = 0;
  int height = 0;
  int channels = 0;
  ASSERT_TRUE(stbi_info(file("office.png").c_str(), &width, &height, &channels));
  EXPECT_EQ(width, 420 * 3);  // 420 x 260 cells, scaled by 3
  EXPECT_EQ(height, 260 * 3);
  EXPECT_EQ(channels, 3);
}

TEST_F(MapToolsCli, ConvertOptionsChangeTheResult)
{
  std::string out;
  std::string err;
  ASSERT_EQ(run(FDML_MAP_CONVERT_EXE,
                kMaps + "office_grid.yaml " + file("all.poly") + " --min-area 0 --tolerance 0.1 --no-preview", &out,
                &err),
            0)
      << err;
  EXPECT_FALSE(fs::exists(file("all.png")));
  // Every speck kept: the 7 obstacles plus the 40 specks.
  EXPECT_EQ(core::loadPolyFile(file("all.poly")).holeCount(), 47u);
}

TEST_F(MapToolsCli, ConvertBadInputExitsTwoNamingTheProblem)
{
  std::string out;
  std::string err;
  EXPECT_EQ(run(FDML_MAP_CONVERT_EXE, file("missing.yaml") + " " + file("o.poly"), &out, &err), 2);
  EXPECT_NE(err.find("missing.yaml: cannot open"), std::string::npos) << err;
  EXPECT_EQ(
      run(FDML_MAP_CONVERT_EXE, kMaps + "office_grid.yaml " + file("o.poly") + " --seed-point 1,nope", &out, &err), 2);
  EXPECT_NE(err.find("--seed-point"), std::string::npos) << err;
  EXPECT_EQ(run(FDML_MAP_CONVERT_EXE, kMaps + "office_grid.yaml " + file("o.poly") + " --seed-point 50,50", &out, &err),
            2);
  EXPECT_NE(err.find("outside the grid"), std::string::npos) << err;
  EXPECT_EQ(run(FDML_MAP_CONVERT_EXE, kMaps + "office_grid.yaml", &out, &err), 2);
  EXPECT_NE(err.find("usage"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(file("o.poly")));
}

TEST_F(MapToolsCli, RasterizeReproducesTheShippedGrid)
{
  std::string out;
  std::string err;
  ASSERT_EQ(run(FDML_MAP_RASTERIZE_EXE,
                kMaps + "office.poly " + file("office_grid.yaml") +
                    " --resolution 0.05 --noise 0.1 --specks 40 --islands 12 --seed 7",
                &out, &err),
            0)
      << err;
  EXPECT_EQ(slurp(file("office_grid.pgm")), slurp(kMaps + "office_grid.pgm"));
  EXPECT_EQ(slurp(file("office_grid.yaml")), slurp(kMaps + "office_grid.yaml"));
  EXPECT_EQ(run(FDML_MAP_RASTERIZE_EXE, kMaps + "office.poly " + file("x.yaml") + " --noise 2", &out, &err), 2);
  EXPECT_NE(err.find("boundary_noise"), std::string::npos) << err;
}
