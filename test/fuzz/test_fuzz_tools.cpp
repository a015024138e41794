// Fuzz, as a user would: the tools run as subprocesses (under a time limit) on mutated readings
// CSV files, .poly maps and map_server YAML + images. Every run must end within the limit with
// exit 0, or exit 2 with a message naming the bad file; never a crash, a hang or exit 1.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"
#include "fuzz_mutator.h"
#include "localizer_test_utils.h"
#include "tool_runner.h"

#include <gtest/gtest.h>
#include <unistd.h>

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

class FuzzTools : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = (fs::temp_directory_path() / ("fdml_fuzz_tools_" + std::to_string(::getpid()))).string();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  std::string file(const std::string& name) const
  {
    return dir_ + "/" + name;
  }

  /// Runs @p exe; exit 0, or 2 with one of @p files named on stderr, else a failure.
  void check(const char* exe, const std::string& args, const std::vector<std::string>& files, Tally& tally,
             const std::string& what)
  {
    ++tally.cases;
    const test::ToolRun run = test::runTool(exe, args, dir_, 60);
    bool named = false;
    for (const std::string& f : files)
    {
      named = named || run.err.find(f) != std::string::npos;
    }
    if (run.code == 0)
    {
      ++tally.accepted;
    }
    else if (run.code == 2 && named)
    {
      ++tally.rejected;
    }
    else
    {
      tally.fail(what + ": exit " + std::to_string(run.code) + ": " + run.err.substr(0, 300));
    }
  }

  std::string dir_;
};

std::string readingsCsv(const core::MapRayCaster& map)
{
  std::ostringstream csv;
  csv.precision(17);
  csv << "gx,gy,gtheta,d,max_range\n";
  for (const core::Reading& r :
       core::test::exactReadings(map, core::Pose2(6.1, 3.2, -0.4), core::test::inPlaceOffsets(6)))
  {
    csv << r.offset.x << "," << r.offset.y << "," << r.offset.theta << "," << r.range << ",20\n";
  }
  return csv.str();
}

void finish(const Tally& tally)
{
  std::cout << tally.report() << std::endl;
  EXPECT_TRUE(tally.failures.empty()) << ::testing::PrintToString(tally.failures);
  EXPECT_GT(tally.accepted, 0);
  EXPECT_GT(tally.rejected, 0);
}
}  // namespace

TEST_F(FuzzTools, LocalizeOnMutatedReadingsAndMaps)
{
  Tally tally{ "fdml_localize" };
  Mutator mutator(1504);
  const auto map = core::test::lRoomMap();
  const std::string map_path = file("room.poly");
  core::savePolyFile(map_path, map->map());
  const std::string csv = readingsCsv(*map);
  const std::string poly = readFile(map_path);
  const int cases = caseCount(0.01, 60);
  for (int c = 0; c < cases; ++c)
  {
    std::string what = "localize case " + std::to_string(c) + ":";
    const bool mutate_map = c % 3 == 2;
    const std::string csv_path = writeFile(file("r.csv"), mutate_map ? csv : mutator.mutateText(csv, what));
    const std::string case_map = writeFile(file("case.poly"), mutate_map ? mutator.mutateText(poly, what) : poly);
    check(FDML_LOCALIZE_EXE, "--resolution 16 --map " + case_map + " " + csv_path, { csv_path, case_map }, tally, what);
  }
  finish(tally);
}

TEST_F(FuzzTools, MapToolsOnMutatedFiles)
{
  Tally tally{ "fdml_map_convert/rasterize" };
  Mutator mutator(1505);
  const std::string base_poly = readFile(std::string(FDML_SOURCE_DIR) + "/maps/l_room.poly");
  const std::string yaml = readFile(std::string(FDML_SOURCE_DIR) + "/maps/office_grid.yaml");
  const std::string pgm = readFile(std::string(FDML_SOURCE_DIR) + "/maps/office_grid.pgm");
  const int cases = caseCount(0.01, 40);
  for (int c = 0; c < cases; ++c)
  {
    std::string what = "map tool case " + std::to_string(c) + ":";
    if (c % 2 == 0)
    {
      const std::string poly = writeFile(file("in.poly"), mutator.mutateText(base_poly, what));
      check(FDML_MAP_RASTERIZE_EXE, poly + " " + file("out.yaml"), { poly }, tally, what);
      continue;
    }
    const bool image = mutator.uniform(0, 1) == 1;
    const std::string y = writeFile(file("office_grid.yaml"), image ? yaml : mutator.mutateText(yaml, what));
    const std::string p = writeFile(file("office_grid.pgm"), image ? mutator.mutateBytes(pgm, what) : pgm);
    // A mutated image name names another file of the folder.
    check(FDML_MAP_CONVERT_EXE, y + " " + file("out.poly") + " --no-preview", { y, p, dir_ + "/" }, tally, what);
  }
  finish(tally);
}

}  // namespace fuzz
}  // namespace fdml_localization
