// The tools on hostile input (issues 15 and 19): --help exits 0, bad input exits 2 with a
// message naming the file and line, a cache that cannot be used never stops a localization.
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "localizer_test_utils.h"
#include "tool_runner.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace fdml_localization
{
namespace core
{
namespace
{
namespace fs = std::filesystem;

class ToolsHardening : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = fs::temp_directory_path() / ("fdml_tools_hardening_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    map_ = test::lRoomMap();
    map_path_ = file("room.poly");
    savePolyFile(map_path_, map_->map());
  }
  void TearDown() override
  {
    fs::remove_all(dir_);
  }
  std::string file(const std::string& name) const
  {
    return (dir_ / name).string();
  }
  std::string write(const std::string& name, const std::string& text) const
  {
    std::ofstream(file(name), std::ios::binary) << text;
    return file(name);
  }
  fdml_localization::test::ToolRun localize(const std::string& args) const
  {
    return fdml_localization::test::runTool(
        FDML_LOCALIZE_EXE, "--map " + map_path_ + " --engine voxel --resolution 24 " + args, dir_.string());
  }
  std::string readingsCsv() const
  {
    std::ostringstream csv;
    csv.precision(17);
    csv << "gx,gy,gtheta,d\n";
    for (const Reading& r : test::exactReadings(*map_, Pose2(6.1, 3.2, -0.4), test::inPlaceOffsets(8)))
    {
      csv << r.offset.x << "," << r.offset.y << "," << r.offset.theta << "," << r.range << "\n";
    }
    return csv.str();
  }

  fs::path dir_;
  std::shared_ptr<const MapRayCaster> map_;
  std::string map_path_;
};

std::size_t count(const std::string& text, const std::string& what)
{
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1))
  {
    ++n;
  }
  return n;
}
}  // namespace

TEST_F(ToolsHardening, HelpPrintsUsageAndExitsZero)
{
  for (const char* exe : { FDML_LOCALIZE_EXE, FDML_MAP_CONVERT_EXE, FDML_MAP_RASTERIZE_EXE })
  {
    for (const char* flag : { "--help", "-h" })
    {
      const fdml_localization::test::ToolRun run = fdml_localization::test::runTool(exe, flag, dir_.string());
      EXPECT_EQ(run.code, 0) << exe << " " << flag << ": " << run.err;
      EXPECT_NE(run.out.find("usage:"), std::string::npos) << exe << " " << flag << ": " << run.out;
    }
    const fdml_localization::test::ToolRun bad =
        fdml_localization::test::runTool(exe, "--no-such-option", dir_.string());
    EXPECT_EQ(bad.code, 2) << exe;
    EXPECT_NE(bad.err.find("unknown option --no-such-option"), std::string::npos) << bad.err;
  }
}

TEST_F(ToolsHardening, ReadingErrorsNameFileAndLineNotTheIndex)
{
  // The second reading (index 1) is on line 5: its range exceeds its max_range.
  const std::string csv = write("r.csv", "# readings\ngx,gy,gtheta,d,max_range\n0,0,0,1,5\n\n0,0,1,7,5\n0,0,2,1,5\n");
  const fdml_localization::test::ToolRun run = localize(csv);
  EXPECT_EQ(run.code, 2) << run.err;
  EXPECT_NE(run.err.find(csv + ":5: range 7 m exceeds max_range 5 m"), std::string::npos) << run.err;
  EXPECT_EQ(run.err.find("reading 1"), std::string::npos) << run.err;
  // Too few readings: the file is named.
  const std::string few = write("few.csv", "gx,gy,gtheta,d\n0,0,0,1\n");
  const fdml_localization::test::ToolRun short_run = localize(few);
  EXPECT_EQ(short_run.code, 2);
  EXPECT_NE(short_run.err.find(few + ": need at least 3 readings"), std::string::npos) << short_run.err;
  // A NUL byte names its line; a FIFO as the readings file is refused, not waited on.
  const std::string nul = write("nul.csv", std::string("gx,gy,gtheta,d\n0,0,0,1\n0,0\0,1,1\n", 33));
  const fdml_localization::test::ToolRun nul_run = localize(nul);
  EXPECT_EQ(nul_run.code, 2);
  EXPECT_NE(nul_run.err.find(nul + ":3: NUL byte"), std::string::npos) << nul_run.err;
  ASSERT_EQ(::mkfifo(file("fifo.csv").c_str(), 0600), 0);
  const fdml_localization::test::ToolRun fifo_run = localize(file("fifo.csv"));
  EXPECT_EQ(fifo_run.code, 2);
  EXPECT_NE(fifo_run.err.find("FIFO"), std::string::npos) << fifo_run.err;
}

TEST_F(ToolsHardening, AnUnusableCacheWarnsOnceAndTheAnswerIsUnchanged)
{
  const std::string csv = write("r.csv", readingsCsv());
  const fdml_localization::test::ToolRun plain = localize(csv);
  ASSERT_EQ(plain.code, 0) << plain.err;
  ASSERT_NE(plain.out.find("\n1,"), std::string::npos) << plain.out;
  // The cache path of this map and grid, made a FIFO: never opened, never replaced.
  const std::string cache = file("cache");
  fs::create_directories(cache);
  const std::string table = tableCachePath(cache, map_->map().hash(), GridSpec::fromMap(map_->map(), 24, 0));
  ASSERT_EQ(::mkfifo(table.c_str(), 0600), 0);
  const fdml_localization::test::ToolRun fifo = localize("--cache-dir " + cache + " " + csv);
  EXPECT_EQ(fifo.code, 0) << fifo.err;
  EXPECT_EQ(fifo.out, plain.out);
  EXPECT_EQ(count(fifo.err, "warning"), 1u) << fifo.err;
  EXPECT_NE(fifo.err.find(table), std::string::npos) << fifo.err;
  EXPECT_NE(fifo.err.find("FIFO"), std::string::npos) << fifo.err;
  // A corrupt cache file: rebuilt with a warning, then loaded silently.
  fs::remove(table);
  ASSERT_EQ(localize("--cache-dir " + cache + " " + csv).err, "");
  fs::resize_file(table, fs::file_size(table) / 2);
  const fdml_localization::test::ToolRun corrupt = localize("--cache-dir " + cache + " " + csv);
  EXPECT_EQ(corrupt.code, 0);
  EXPECT_EQ(corrupt.out, plain.out);
  EXPECT_NE(corrupt.err.find("truncated"), std::string::npos) << corrupt.err;
  EXPECT_EQ(count(corrupt.err, "warning"), 1u) << corrupt.err;
  EXPECT_EQ(localize("--cache-dir " + cache + " " + csv).err, "");
}

}  // namespace core
}  // namespace fdml_localization
