// fdml_localize's optional fov column (issue 18): the full field of view [deg] of each reading;
// a zero fov gives exactly the output without the column, a bad one is an error naming the file,
// the line and the column.
#include "localizer_test_utils.h"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
struct ToolRun
{
  int code = -1;
  std::string out;
  std::string err;
};

ToolRun runLocalize(const std::filesystem::path& dir, const std::string& args)
{
  const std::string out_path = (dir / "out.txt").string();
  const std::string err_path = (dir / "err.txt").string();
  const int status =
      std::system((std::string(FDML_LOCALIZE_EXE) + " " + args + " > " + out_path + " 2> " + err_path).c_str());
  ToolRun run;
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::stringstream o, e;
  o << std::ifstream(out_path).rdbuf();
  e << std::ifstream(err_path).rdbuf();
  run.out = o.str();
  run.err = e.str();
  return run;
}

/// The readings of @p truth in the L room with the optional columns given as suffixes.
std::string readingsCsv(const MapRayCaster& map, const Pose2& truth, const std::string& header_suffix,
                        const std::string& row_suffix)
{
  std::ostringstream csv;
  csv.precision(17);
  csv << "gx,gy,gtheta,d" << header_suffix << "\n";
  for (const Reading& r : test::exactReadings(map, truth, test::inPlaceOffsets(10)))
  {
    csv << r.offset.x << "," << r.offset.y << "," << r.offset.theta << "," << r.range << row_suffix << "\n";
  }
  return csv.str();
}

TEST(LocalizeFov, ZeroFovColumnGivesTheSameAnswerAndBadValuesAreErrors)
{
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("fdml_localize_fov_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto map = test::lRoomMap();
  const std::string map_path = (dir / "room.poly").string();
  savePolyFile(map_path, map->map());
  const Pose2 truth(6.1, 3.2, -0.4);
  const auto write = [&dir](const std::string& name, const std::string& text) {
    std::ofstream((dir / name).string()) << text;
    return (dir / name).string();
  };
  const std::string args = "--map " + map_path + " --resolution 48 --threads 1 ";
  const ToolRun plain = runLocalize(dir, args + write("plain.csv", readingsCsv(*map, truth, "", "")));
  ASSERT_EQ(plain.code, 0) << plain.err;
  const ToolRun fov = runLocalize(dir, args + write("fov.csv", readingsCsv(*map, truth, ",fov", ",0")));
  EXPECT_EQ(fov.code, 0) << fov.err;
  EXPECT_EQ(fov.out, plain.out);
  const ToolRun both = runLocalize(dir, args + write("both.csv", readingsCsv(*map, truth, ",max_range,fov", ",20,0")));
  EXPECT_EQ(both.code, 0) << both.err;
  EXPECT_EQ(both.out, plain.out);

  const ToolRun wide = runLocalize(dir, args + write("wide.csv", readingsCsv(*map, truth, ",fov", ",181")));
  EXPECT_EQ(wide.code, 2);
  EXPECT_NE(wide.err.find("wide.csv:2: fov must be in [0, 180] degrees"), std::string::npos) << wide.err;
  const ToolRun nan = runLocalize(dir, args + write("nan.csv", readingsCsv(*map, truth, ",fov", ",nan")));
  EXPECT_EQ(nan.code, 2);
  EXPECT_NE(nan.err.find("nan.csv:2: fov"), std::string::npos) << nan.err;
  const ToolRun order =
      runLocalize(dir, args + write("order.csv", readingsCsv(*map, truth, ",fov,max_range", ",0,20")));
  EXPECT_EQ(order.code, 2);
  EXPECT_NE(order.err.find("order.csv:1: expected the header"), std::string::npos) << order.err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
