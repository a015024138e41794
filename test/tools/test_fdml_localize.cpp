// The fdml_localize command-line tool: output format, exit codes and error messages.
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
class LocalizeCli : public ::testing::Test
{
protected:
  void SetUp() override
  {
    dir_ = std::filesystem::temp_directory_path() / ("fdml_localize_cli_" + std::to_string(::getpid()));
    std::filesystem::remove_all(dir_);
    std::filesystem::create_directories(dir_);
    map_ = test::lRoomMap();
    map_path_ = (dir_ / "room.poly").string();
    savePolyFile(map_path_, map_->map());
  }
  void TearDown() override
  {
    std::filesystem::remove_all(dir_);
  }

  std::string write(const std::string& name, const std::string& text)
  {
    const std::string path = (dir_ / name).string();
    std::ofstream(path) << text;
    return path;
  }

  /// Runs the tool; returns its exit code and fills out / err.
  int run(const std::string& args, std::string& out, std::string& err)
  {
    const std::string out_path = (dir_ / "out.txt").string();
    const std::string err_path = (dir_ / "err.txt").string();
    const std::string command = std::string(FDML_LOCALIZE_EXE) + " " + args + " > " + out_path + " 2> " + err_path;
    const int status = std::system(command.c_str());
    std::stringstream o;
    o << std::ifstream(out_path).rdbuf();
    std::stringstream e;
    e << std::ifstream(err_path).rdbuf();
    out = o.str();
    err = e.str();
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

  std::string readingsCsv(const Pose2& truth)
  {
    std::ostringstream csv;
    csv.precision(17);
    csv << "gx,gy,gtheta,d\n";
    for (const Reading& r : test::exactReadings(*map_, truth, test::inPlaceOffsets(10)))
    {
      csv << r.offset.x << "," << r.offset.y << "," << r.offset.theta << "," << r.range << "\n";
    }
    return csv.str();
  }

  std::filesystem::path dir_;
  std::shared_ptr<const MapRayCaster> map_;
  std::string map_path_;
};

TEST_F(LocalizeCli, PrintsCandidatesBestFirst)
{
  const Pose2 truth(6.1, 3.2, -0.4);
  const std::string csv = write("r.csv", readingsCsv(truth));
  std::string out;
  std::string err;
  ASSERT_EQ(run("--map " + map_path_ +
                    " --resolution 48 --min-inliers auto --method robust "
                    "--range-tolerance 0.02 --tolerance 0.05 --threads 1 --engine voxel " +
                    csv,
                out, err),
            0)
      << err;
  std::istringstream lines(out);
  std::string header;
  std::string first;
  std::getline(lines, header);
  std::getline(lines, first);
  EXPECT_EQ(header, "rank,x,y,theta,inliers,rms,unambiguous");
  int rank = 0;
  double x = 0;
  double y = 0;
  double theta = 0;
  int inliers = 0;
  double rms = 0;
  int unambiguous = -1;
  ASSERT_EQ(std::sscanf(first.c_str(), "%d,%lf,%lf,%lf,%d,%lf,%d", &rank, &x, &y, &theta, &inliers, &rms, &unambiguous),
            7)
      << first;
  // Ten exact readings in the asymmetric L-room: one place explains them all.
  EXPECT_EQ(unambiguous, 1) << out;
  EXPECT_EQ(rank, 1);
  EXPECT_NEAR(x, truth.x, 1e-3);
  EXPECT_NEAR(y, truth.y, 1e-3);
  EXPECT_NEAR(theta, truth.theta, 1e-3);
  EXPECT_EQ(inliers, 10);
}

TEST_F(LocalizeCli, NoCandidateStillExitsZero)
{
  // Ten readings of 100 m fit nowhere in an 8 x 6 m room.
  std::string text = "gx,gy,gtheta,d\n";
  for (int i = 0; i < 10; ++i)
  {
    text += "0,0," + std::to_string(0.6 * i - 3.0) + ",100\n";
  }
  std::string out;
  std::string err;
  EXPECT_EQ(run("--map " + map_path_ + " --resolution 24 " + write("far.csv", text), out, err), 0) << err;
  EXPECT_EQ(out, "rank,x,y,theta,inliers,rms,unambiguous\n");
}

TEST_F(LocalizeCli, BadInputExitsTwoWithAMessage)
{
  const std::string good = write("good.csv", readingsCsv(Pose2(2, 1, 0)));
  struct Case
  {
    std::string args;
    std::string needle;
  };
  const std::vector<Case> cases = {
    { "--map " + map_path_ + " " + write("nan.csv", "gx,gy,gtheta,d\n0,0,0,1\n0,0,1,nan\n0,0,2,1\n"), "nan.csv:3" },
    { "--map " + map_path_ + " " + write("neg.csv", "gx,gy,gtheta,d\n0,0,0,1\n0,0,1,-2\n0,0,2,1\n"), "neg.csv:3" },
    { "--map " + map_path_ + " " + write("hdr.csv", "x,y,t,d\n0,0,0,1\n"), "header" },
    { "--map " + map_path_ + " " + write("few.csv", "gx,gy,gtheta,d\n0,0,0,1\n0,0,1,2\n"), "at least 3" },
    { "--map " + map_path_ + " " + write("cols.csv", "gx,gy,gtheta,d\n0,0,0\n"), "expected 4 fields" },
    { "--map " + map_path_ + " " + write("inf.csv", "gx,gy,gtheta,d\n0,0,0,inf\n0,0,1,1\n0,0,2,1\n"), "max range" },
    { "--map " + map_path_ + " --resolution 8 " + good, "--resolution = 8 is out of range" },
    { "--map " + map_path_ + " --resolution abc " + good, "not an integer" },
    { "--map " + map_path_ + " --min-inliers 11 " + good, "exceeds the number of readings" },
    { "--map " + map_path_ + " --min-inliers 2 " + good, "--min-inliers" },
    { "--map " + map_path_ + " --method fancy " + good, "unknown method" },
    { "--map " + map_path_ + " --engine warp " + good, "unknown engine" },
    { "--map " + map_path_ + " --method paper " + good, "a fixed k' in [3, the number of readings] with --method "
                                                        "paper" },
    { "--map " + (dir_ / "missing.poly").string() + " " + good, "missing.poly" },
    { "--map " + map_path_ + " " + (dir_ / "missing.csv").string(), "missing.csv" },
    { "--map " + map_path_, "READINGS.csv" },
    { good, "--map" },
    { "--map " + map_path_ + " --bogus " + good, "unknown option --bogus" },
  };
  for (const Case& c : cases)
  {
    std::string out;
    std::string err;
    EXPECT_EQ(run(c.args, out, err), 2) << c.args;
    EXPECT_NE(err.find(c.needle), std::string::npos) << c.args << "\n" << err;
    EXPECT_EQ(out, "") << c.args;
  }
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
