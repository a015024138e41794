// Parameter validation of the localizer node (pure, no roscore).
#include "params_test_utils.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

namespace fdml_localization
{
namespace
{
using test::errorsNaming;
using test::validParams;

TEST(Params, DefaultsAreValidOnceTheMapIsGiven)
{
  EXPECT_TRUE(validate(validParams()).empty());
  const std::vector<std::string> errors = validate(Params());
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("~map_file"), std::string::npos);
  EXPECT_NE(errors[0].find("required"), std::string::npos);
}

TEST(Params, EachOutOfRangeValueNamesItsParameterAndRange)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<test::ParamCase> cases = {
    { "measurements_per_batch", [](Params& p) { p.measurements_per_batch = 2; }, "[3, 255]" },
    { "measurements_per_batch", [](Params& p) { p.measurements_per_batch = 256; }, "[3, 255]" },
    { "batch_stride", [](Params& p) { p.batch_stride = 11; }, "[1, ~measurements_per_batch]" },
    { "batch_stride", [](Params& p) { p.batch_stride = 0; }, "[1, ~measurements_per_batch]" },
    { "mode", [](Params& p) { p.mode = "sometimes"; }, "\"on_request\" or \"continuous\"" },
    { "beams_per_scan", [](Params& p) { p.beams_per_scan = 0; }, "[1, 1000]" },
    { "transform_tolerance", [](Params& p) { p.transform_tolerance = -0.1; }, "[0, 10] s" },
    { "transform_tolerance", [nan](Params& p) { p.transform_tolerance = nan; }, "[0, 10] s" },
    { "future_tolerance", [](Params& p) { p.future_tolerance = -0.1; }, "[0, 3600] s" },
    { "future_tolerance", [nan](Params& p) { p.future_tolerance = nan; }, "[0, 3600] s" },
    { "max_sensor_frames", [](Params& p) { p.max_sensor_frames = 0; }, "[1, 1000000]" },
    { "relocalize_timeout", [](Params& p) { p.relocalize_timeout = 0.0; }, "(0, 3600] s" },
    { "tf_publish_rate", [](Params& p) { p.tf_publish_rate = 0.0; }, "(0, 1000] Hz" },
    { "global_frame_id", [](Params& p) { p.global_frame_id = ""; }, "non-empty" },
    { "base_frame_id", [](Params& p) { p.base_frame_id = "base link"; }, "without spaces" },
    { "odom_frame_id", [](Params& p) { p.odom_frame_id = "base_link"; }, "different" },
    { "range_topic", [](Params& p) { p.range_topic = ""; }, "non-empty" },
    { "engine", [](Params& p) { p.engine = "quantum"; }, "\"voxel\", \"adaptive\" or \"auto\"" },
    { "method", [](Params& p) { p.method = "magic"; }, "\"robust\", \"paper\" or \"baseline\"" },
    { "resolution", [](Params& p) { p.localizer.resolution = 15; }, "[16, 100000] for engine adaptive" },
    { "resolution",
      [](Params& p) {
        p.engine = "voxel";
        p.localizer.resolution = 1025;
      },
      "[16, 1024] for engine voxel" },
    { "resolution",
      [](Params& p) {
        p.method = "paper";  // auto: the voxel engine
        p.localizer.min_inliers = 5;
        p.localizer.resolution = 1025;
      },
      "[16, 1024] for engine voxel" },
    { "theta_resolution", [](Params& p) { p.localizer.theta_resolution = 15; }, "[16, 100000]" },
    { "min_inliers", [](Params& p) { p.localizer.min_inliers = 2; }, "[3, ~measurements_per_batch]" },
    { "min_inliers", [](Params& p) { p.localizer.min_inliers = 11; }, "[3, ~measurements_per_batch]" },
    { "min_inliers", [](Params& p) { p.method = "paper"; }, "with ~method paper" },
    { "agreement_tolerance", [](Params& p) { p.localizer.agreement_tolerance = 0.0; }, "(0, 1e6] m" },
    { "uniqueness_distance", [](Params& p) { p.localizer.uniqueness_distance = -1.0; }, "[0, 100] m" },
    { "uniqueness_angle", [](Params& p) { p.localizer.uniqueness_angle = 4.0; }, "[0, pi] rad" },
    { "range_tolerance", [](Params& p) { p.localizer.range_tolerance = -0.01; }, "[0, 10] m" },
    { "max_candidates", [](Params& p) { p.localizer.max_candidates = 0; }, "[1, 1000000]" },
    { "threads", [](Params& p) { p.localizer.threads = -1; }, "[1, 1024]" },
    { "max_boxes", [](Params& p) { p.localizer.max_boxes = 10; }, ">= 1000" },
    { "deadline", [](Params& p) { p.localizer.deadline = -1.0; }, "(0, 3600] s" },
  };
  test::expectEachCaseNamed(cases);
}

TEST(Params, EveryProblemIsReportedAtOnce)
{
  Params params;
  params.localizer.resolution = 3;
  params.mode = "x";
  params.localizer.agreement_tolerance = -1.0;
  params.measurements_per_batch = 10;
  params.localizer.min_inliers = 12;
  const std::vector<std::string> errors = validate(params);
  EXPECT_EQ(errors.size(), 5u);
  for (const char* name : { "map_file", "resolution", "mode", "agreement_tolerance", "min_inliers" })
  {
    bool found = false;
    for (const std::string& error : errors)
    {
      found = found || error.find(std::string("~") + name) != std::string::npos;
    }
    EXPECT_TRUE(found) << name;
  }
}

TEST(Params, LimitsAreInclusive)
{
  Params params = validParams();
  params.measurements_per_batch = 3;
  params.batch_stride = 3;
  params.localizer.min_inliers = 3;
  params.localizer.resolution = 16;
  params.localizer.theta_resolution = 1024;
  params.measurements_per_batch = 255;
  EXPECT_TRUE(validate(params).empty());
  params.measurements_per_batch = 3;
  params.localizer.theta_resolution = 16;
  params.transform_tolerance = 0.0;
  params.mode = "continuous";
  EXPECT_TRUE(validate(params).empty());
}

TEST(Params, CoreOptionsAreCopied)
{
  Params params = validParams();
  params.engine = "adaptive";
  params.method = "baseline";
  params.localizer.resolution = 64;
  params.localizer.theta_resolution = 72;
  params.localizer.min_inliers = 6;
  params.localizer.agreement_tolerance = 0.03;
  params.localizer.uniqueness_distance = 0.2;
  params.localizer.uniqueness_angle = 0.3;
  params.localizer.range_tolerance = 0.04;
  params.localizer.max_candidates = 5;
  params.localizer.threads = 2;
  params.localizer.cache_dir = "/tmp/cache";
  params.localizer.max_boxes = 5000;
  params.localizer.deadline = 1.5;
  const core::Ring square = { { 0, 0 }, { 1, 0 }, { 1, 1 }, { 0, 1 } };
  params.search_region_map = std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings({ square }));
  const core::LocalizerOptions options = toLocalizerOptions(params);
  EXPECT_EQ(options.search_region, params.search_region_map);
  EXPECT_EQ(options.engine, core::Engine::Adaptive);
  EXPECT_EQ(options.method, core::Method::Baseline);
  EXPECT_EQ(options.resolution, 64);
  EXPECT_EQ(options.theta_resolution, 72);
  EXPECT_EQ(options.min_inliers, 6);
  EXPECT_EQ(options.agreement_tolerance, 0.03);
  EXPECT_EQ(options.uniqueness_distance, 0.2);
  EXPECT_EQ(options.uniqueness_angle, 0.3);
  EXPECT_EQ(options.range_tolerance, 0.04);
  EXPECT_EQ(options.max_candidates, 5);
  EXPECT_EQ(options.threads, 2);
  EXPECT_EQ(options.cache_dir, "/tmp/cache");
  EXPECT_EQ(options.max_boxes, 5000);
  EXPECT_EQ(options.deadline, 1.5);
  params.method = "paper";
  params.engine = "voxel";
  EXPECT_EQ(toLocalizerOptions(params).method, core::Method::Paper);
  EXPECT_EQ(toLocalizerOptions(params).engine, core::Engine::Voxel);
}

TEST(Params, AcceptsOnlyWhatTheCoreAccepts)
{
  // What the node accepts, the core accepts.
  std::vector<std::function<void(Params&)>> accepted = {
    [](Params&) {},
    [](Params& p) {
      p.localizer.resolution = 16;
      p.localizer.theta_resolution = 1024;
      p.localizer.min_inliers = 3;
    },
    [](Params& p) {
      p.localizer.resolution = 1024;
      p.localizer.theta_resolution = 16;
      p.measurements_per_batch = 255;
      p.localizer.min_inliers = 255;
    },
    [](Params& p) {
      p.method = "paper";
      p.localizer.min_inliers = 6;
    },
    [](Params& p) { p.method = "baseline"; },
    [](Params& p) {
      p.engine = "adaptive";
      p.localizer.resolution = 100000;
      p.localizer.theta_resolution = 7200;
    },
    [](Params& p) {
      p.localizer.agreement_tolerance = 10.0;
      p.localizer.uniqueness_distance = 0.0;
      p.localizer.uniqueness_angle = 0.0;
      p.localizer.range_tolerance = 0.0;
      p.localizer.max_candidates = 1;
      p.localizer.threads = 1;
      p.localizer.max_boxes = 1000;
      p.localizer.deadline = 3600.0;
    },
  };
  for (std::size_t i = 0; i < accepted.size(); ++i)
  {
    Params params = validParams();
    accepted[i](params);
    EXPECT_TRUE(validate(params).empty()) << i;
    const std::vector<std::string> core_errors = core::validate(toLocalizerOptions(params));
    EXPECT_TRUE(core_errors.empty()) << i << ": " << (core_errors.empty() ? "" : core_errors[0]);
  }
}

TEST(Params, RejectsWhatTheCoreRejects)
{
  // Every core option the core rejects, the node rejects first (naming the parameter).
  std::vector<std::function<void(Params&)>> rejected = {
    [](Params& p) { p.localizer.resolution = 15; },
    [](Params& p) {
      p.engine = "voxel";
      p.localizer.resolution = 1025;
    },
    [](Params& p) {
      p.engine = "adaptive";
      p.localizer.resolution = 100001;
    },
    [](Params& p) { p.localizer.theta_resolution = 15; },
    [](Params& p) { p.localizer.min_inliers = 2; },
    [](Params& p) { p.localizer.agreement_tolerance = 0.0; },
    [](Params& p) { p.localizer.uniqueness_distance = -1.0; },
    [](Params& p) { p.localizer.uniqueness_angle = -1.0; },
    [](Params& p) { p.localizer.range_tolerance = -0.01; },
    [](Params& p) { p.localizer.max_candidates = 0; },
    [](Params& p) { p.localizer.threads = -1; },
    [](Params& p) { p.localizer.max_boxes = 999; },
    [](Params& p) { p.localizer.deadline = -1.0; },
    [](Params& p) { p.method = "paper"; },
  };
  for (std::size_t i = 0; i < rejected.size(); ++i)
  {
    Params params = validParams();
    rejected[i](params);
    EXPECT_FALSE(core::validate(toLocalizerOptions(params)).empty()) << i;
    EXPECT_FALSE(validate(params).empty()) << i;
  }
}

TEST(Params, ModeParsing)
{
  SolveMode mode = SolveMode::OnRequest;
  EXPECT_TRUE(parseSolveMode("continuous", &mode));
  EXPECT_EQ(mode, SolveMode::Continuous);
  EXPECT_TRUE(parseSolveMode("on_request", &mode));
  EXPECT_EQ(mode, SolveMode::OnRequest);
  EXPECT_FALSE(parseSolveMode("Continuous", &mode));
  EXPECT_STREQ(toString(SolveMode::Continuous), "continuous");
}

TEST(Params, CacheDirExpansion)
{
  EXPECT_EQ(expandUser("~/.ros/x", "/home/u"), "/home/u/.ros/x");
  EXPECT_EQ(expandUser("~", "/home/u"), "/home/u");
  EXPECT_EQ(expandUser("/abs/~/x", "/home/u"), "/abs/~/x");
  EXPECT_EQ(expandUser("~other/x", "/home/u"), "~other/x");
  EXPECT_EQ(defaultCacheDir("/ros_home", "/home/u"), "/ros_home/fdml_localization");
  EXPECT_EQ(defaultCacheDir("", "/home/u"), "/home/u/.ros/fdml_localization");
}

TEST(Params, DescribeListsEveryParameter)
{
  const std::string text = describe(validParams());
  for (const char* name : { "map_file",
                            "measurements_per_batch",
                            "batch_stride",
                            "mode",
                            "beams_per_scan",
                            "transform_tolerance",
                            "relocalize_timeout",
                            "publish_tf",
                            "engine",
                            "method",
                            "resolution",
                            "theta_resolution",
                            "min_inliers",
                            "agreement_tolerance",
                            "uniqueness_distance",
                            "uniqueness_angle",
                            "range_tolerance",
                            "max_candidates",
                            "threads",
                            "cache_dir",
                            "max_boxes",
                            "deadline" })
  {
    EXPECT_NE(text.find(name), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace fdml_localization
