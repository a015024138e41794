// Fuzz, in process: mutated .poly files, and map_server YAML files with PGM or PNG images
// (truncated, bit-flipped, NUL bytes, huge numbers and dimensions, crossing rings). Every case
// must load a valid map or throw a MapError naming the file (and for .poly a line within it);
// any other exception, a crash or a sanitizer report is a failure.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"
#include "fuzz_mutator.h"

#include "temp_dir_test.h"

#include <gtest/gtest.h>
#include <stb/stb_image_write.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <iostream>
#include <sstream>

namespace fdml_localization
{
namespace fuzz
{
namespace
{
namespace fs = std::filesystem;
using core::MapError;

class FuzzMaps : public fdml_localization::test::TempDirTest
{};

std::vector<std::string> bundledPolyTexts()
{
  std::vector<std::string> texts;
  for (const char* name : { "l_room.poly", "office.poly", "square_room.poly", "corridor.poly", "apartment.poly" })
  {
    texts.push_back(readFile(std::string(FDML_SOURCE_DIR) + "/maps/" + name));
  }
  return texts;
}

std::size_t lineCount(const std::string& text)
{
  return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')) + 1;
}

/// A valid map must also pass the validation on its own rings (a right answer, not garbage).
void checkLoaded(const core::PolygonMap& map, Tally& tally, const std::string& what)
{
  if (map.rings().empty() || !core::validateRings(map.rings()).empty() || !(map.area() > 0.0))
  {
    tally.fail(what + ": loaded an invalid map");
  }
  ++tally.accepted;
}

/// A rejection must name its file first and, when @p lines > 0, a line within it: one of
/// @p files, or another file (an image a mutated YAML names) with @p files[0] named too.
void checkRejected(const MapError& e, const std::vector<std::string>& files, std::size_t lines, Tally& tally,
                   const std::string& what)
{
  const std::string message = e.what();
  const bool named = !e.file().empty() && message.rfind(e.file(), 0) == 0 &&
                     (std::find(files.begin(), files.end(), e.file()) != files.end() ||
                      message.find(files.front(), e.file().size()) != std::string::npos);
  if (!named || e.line() < 0 || (lines > 0 && static_cast<std::size_t>(e.line()) > lines))
  {
    tally.fail(what + ": message does not name the file and a line in it: " + message);
  }
  ++tally.rejected;
}

/// A small occupancy grid: a room with a pillar, at 5 cm.
core::OccupancyGrid roomGrid()
{
  core::OccupancyGrid grid;
  grid.width = 36;
  grid.height = 28;
  grid.resolution = 0.05;
  grid.cells.assign(static_cast<std::size_t>(grid.width * grid.height), 0);
  for (int y = 0; y < grid.height; ++y)
  {
    for (int x = 0; x < grid.width; ++x)
    {
      const bool wall = x < 2 || y < 2 || x >= grid.width - 2 || y >= grid.height - 2;
      const bool pillar = x >= 15 && x < 20 && y >= 10 && y < 15;
      grid.cells[static_cast<std::size_t>(y * grid.width + x)] = wall || pillar ? 100 : 0;
    }
  }
  return grid;
}
}  // namespace

TEST_F(FuzzMaps, MutatedPolyFiles)
{
  Tally tally{ "poly" };
  Mutator mutator(1501);
  const std::vector<std::string> bases = bundledPolyTexts();
  const int cases = caseCount(0.75, 3000);
  for (int c = 0; c < cases; ++c)
  {
    std::string what = "poly case " + std::to_string(c) + ":";
    const std::string text = mutator.mutateText(bases[static_cast<std::size_t>(c) % bases.size()], what);
    const bool through_file = c % 8 == 0;
    const std::string source = through_file ? writeFile(file("case.poly"), text) : "case.poly";
    ++tally.cases;
    try
    {
      std::istringstream in(text);
      checkLoaded(through_file ? core::loadPolyFile(source) : core::parsePoly(in, source), tally, what);
    }
    catch (const MapError& e)
    {
      checkRejected(e, { source }, lineCount(text), tally, what);
    }
    catch (const std::exception& e)
    {
      tally.fail(what + ": " + typeid(e).name() + ": " + e.what());
    }
  }
  std::cout << tally.report() << std::endl;
  EXPECT_TRUE(tally.failures.empty()) << ::testing::PrintToString(tally.failures);
  EXPECT_GT(tally.accepted, 0);
  EXPECT_GT(tally.rejected, 0);
}

TEST_F(FuzzMaps, MutatedYamlAndImages)
{
  Tally tally{ "yaml+image" };
  Mutator mutator(1502);
  const core::OccupancyGrid grid = roomGrid();
  io::saveOccupancyGridYaml(file("base.yaml"), grid);
  const std::string yaml_text = readFile(file("base.yaml"));
  const std::string pgm = readFile(file("base.pgm"));
  std::vector<unsigned char> grey(grid.cells.size());
  std::transform(grid.cells.begin(), grid.cells.end(), grey.begin(),
                 [](std::int8_t v) { return static_cast<unsigned char>(v == 0 ? 254 : 0); });
  ASSERT_TRUE(stbi_write_png(file("base.png").c_str(), grid.width, grid.height, 1, grey.data(), grid.width));
  const std::string png = readFile(file("base.png"));
  const int cases = caseCount(0.2, 500);
  for (int c = 0; c < cases; ++c)
  {
    std::string what = "yaml case " + std::to_string(c) + ":";
    const bool use_png = c % 2 == 1;
    const std::string image_name = use_png ? "case.png" : "case.pgm";
    std::string yaml = yaml_text;
    yaml.replace(yaml.find("base.pgm"), 8, image_name);
    std::string image = use_png ? png : pgm;
    switch (mutator.uniform(0, 2))
    {
      case 0:
        yaml = mutator.mutateText(yaml, what += " yaml");
        break;
      case 1:
        image = mutator.mutateBytes(image, what += " image");
        break;
      default:
        yaml = mutator.mutateText(yaml, what += " yaml");
        image = mutator.mutateBytes(image, what += " image");
    }
    const std::string yaml_path = writeFile(file("case.yaml"), yaml);
    writeFile(file(image_name), image);
    ++tally.cases;
    try
    {
      checkLoaded(io::loadMapFile(yaml_path), tally, what);
    }
    catch (const MapError& e)
    {
      checkRejected(e, { yaml_path, file(image_name) }, 0, tally, what);
    }
    catch (const std::exception& e)
    {
      tally.fail(what + ": " + typeid(e).name() + ": " + e.what());
    }
  }
  std::cout << tally.report() << std::endl;
  EXPECT_TRUE(tally.failures.empty()) << ::testing::PrintToString(tally.failures);
  EXPECT_GT(tally.accepted, 0);
  EXPECT_GT(tally.rejected, 0);
}

}  // namespace fuzz
}  // namespace fdml_localization
