// rostest: the fdml_localizer binary exits non-zero, naming the problem, for a missing map file,
// a map_server YAML whose image is missing, an out-of-range parameter, a parameter of the wrong
// type and a missing ~map_file; fdml_simulator does for an odometry frame equal to the base frame
// (each run as a child process against the rostest's master).
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <string>

namespace
{
struct RunResult
{
  int exit_code = -1;
  std::string output;
};

/// Runs @p binary with @p args (at most 60 s) and returns its exit code and its stdout + stderr.
RunResult runBinary(const std::string& binary, const std::string& args)
{
  const std::string command = "timeout 60 " + binary + " " + args + " 2>&1";
  RunResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe)
  {
    return result;
  }
  std::array<char, 512> chunk;
  while (std::fgets(chunk.data(), static_cast<int>(chunk.size()), pipe))
  {
    result.output += chunk.data();
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

/// Runs fdml_localizer with @p args.
RunResult runNode(const std::string& args)
{
  return runBinary(FDML_LOCALIZER_BINARY, args);
}

const std::string kGoodMap = std::string(FDML_SOURCE_DIR) + "/test/data/node_test_room.poly";

TEST(LocalizerBadParams, MissingMapFileExitsNonZeroNamingTheFile)
{
  const RunResult run = runNode("__name:=missing_map _map_file:=/nonexistent/fdml/room.poly");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find("/nonexistent/fdml/room.poly"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("~map_file"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, UnknownPackageExitsNonZeroNamingIt)
{
  const RunResult run = runNode("__name:=bad_package _map_file:=package://no_such_fdml_package/maps/x.poly");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find("no_such_fdml_package"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, OutOfRangeParameterExitsNonZeroNamingItAndItsRange)
{
  const RunResult run = runNode("__name:=bad_resolution _map_file:=" + kGoodMap + " _resolution:=5 _mode:=sometimes");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find("~resolution = 5"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("[16, 100000] for engine adaptive"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("~mode"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, UnusableSearchRegionExitsNonZeroNamingIt)
{
  const RunResult missing =
      runNode("__name:=missing_region _map_file:=" + kGoodMap + " _search_region:=/nonexistent/fdml/region.poly");
  EXPECT_NE(missing.exit_code, 0) << missing.output;
  EXPECT_NE(missing.exit_code, 124) << "timed out: " << missing.output;
  EXPECT_NE(missing.output.find("~search_region"), std::string::npos) << missing.output;
  EXPECT_NE(missing.output.find("/nonexistent/fdml/region.poly"), std::string::npos) << missing.output;
  // A region that does not overlap the map (the test room moved far away).
  const std::string away = "/tmp/fdml_bad_region_" + std::to_string(::getpid()) + ".poly";
  FILE* file = std::fopen(away.c_str(), "w");
  ASSERT_NE(file, nullptr);
  std::fputs("1000 1000\n1001 1000\n1001 1001\n1000 1001\n", file);
  std::fclose(file);
  const RunResult outside = runNode("__name:=outside_region _map_file:=" + kGoodMap + " _search_region:=" + away);
  std::remove(away.c_str());
  EXPECT_NE(outside.exit_code, 0) << outside.output;
  EXPECT_NE(outside.exit_code, 124) << "timed out: " << outside.output;
  EXPECT_NE(outside.output.find("search region"), std::string::npos) << outside.output;
  const RunResult seed = runNode("__name:=seed_only _map_file:=" + kGoodMap + " _search_region_seed:=[1.0,1.0]");
  EXPECT_NE(seed.exit_code, 0) << seed.output;
  EXPECT_NE(seed.output.find("~search_region_seed"), std::string::npos) << seed.output;
}

TEST(LocalizerBadParams, WrongTypesExitNonZeroNamingTheParameterAndTheType)
{
  // Before issue 15 both were silently replaced by their defaults and the node ran.
  const RunResult run = runNode("__name:=bad_types _map_file:=" + kGoodMap + " _resolution:=abc _mode:=3");
  EXPECT_EQ(run.exit_code, 2) << run.output;
  EXPECT_NE(run.output.find("~resolution: expected an integer"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("got a string (\"abc\")"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("~mode: expected a string, got an integer (3)"), std::string::npos) << run.output;
}

TEST(SimulatorBadParams, OdometryFrameEqualToTheBaseIsRefusedNamingBoth)
{
  const RunResult run = runBinary(FDML_SIMULATOR_BINARY, "__name:=bad_frames _map_file:=" + kGoodMap +
                                                             " _scan/enabled:=true _frames/odom:=base_link "
                                                             "_frames/base:=base_link");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find("frames.odom = \"base_link\" equals frames.base"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, MissingMapParameterExitsNonZero)
{
  const RunResult run = runNode("__name:=no_map");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find("~map_file is required"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, InvalidMapContentExitsNonZeroNamingTheLine)
{
  const std::string path = "/tmp/fdml_bad_map_" + std::to_string(::getpid()) + ".poly";
  FILE* file = std::fopen(path.c_str(), "w");
  ASSERT_NE(file, nullptr);
  std::fputs("0 0\n4 0\nfour 3\n0 3\n", file);
  std::fclose(file);
  const RunResult run = runNode("__name:=bad_content _map_file:=" + path);
  std::remove(path.c_str());
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find(path + ":3"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, YamlWithAMissingImageExitsNonZeroNamingTheImage)
{
  const std::string stem = "/tmp/fdml_bad_yaml_" + std::to_string(::getpid());
  const std::string path = stem + ".yaml";
  FILE* file = std::fopen(path.c_str(), "w");
  ASSERT_NE(file, nullptr);
  std::fputs(("image: " + stem +
              "_missing.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\n"
              "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
                 .c_str(),
             file);
  std::fclose(file);
  const RunResult run = runNode("__name:=bad_yaml _map_file:=" + path);
  std::remove(path.c_str());
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find(stem + "_missing.pgm"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("image file not found"), std::string::npos) << run.output;
}

TEST(LocalizerBadParams, BadGridConversionParametersExitNonZeroNamingThem)
{
  const RunResult run = runNode("__name:=bad_grid_params _use_map_topic:=true _map_simplify_tolerance:=-1 "
                                "_map_occupied_threshold:=0");
  EXPECT_NE(run.exit_code, 0) << run.output;
  EXPECT_NE(run.exit_code, 124) << "timed out: " << run.output;
  EXPECT_NE(run.output.find("~map_simplify_tolerance = -1"), std::string::npos) << run.output;
  EXPECT_NE(run.output.find("~map_occupied_threshold = 0"), std::string::npos) << run.output;
  EXPECT_EQ(run.output.find("~map_file is required"), std::string::npos) << run.output;
}

}  // namespace

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_localizer_bad_params");
  return RUN_ALL_TESTS();
}
