// Parameters of occupancy-grid maps (issue 9): validation and the core options they give (no roscore).
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

// ---------------------------------------------------------------------------------------------
// Occupancy-grid maps (issue 9).
// ---------------------------------------------------------------------------------------------

TEST(Params, MapTopicMakesTheMapFileOptional)
{
  Params params;
  params.use_map_topic = true;
  EXPECT_TRUE(validate(params).empty());
  params.map_file = "package://fdml_localization/maps/office_grid.yaml";  // an initial map
  EXPECT_TRUE(validate(params).empty());
  params.use_map_topic = false;
  params.map_file.clear();
  const std::vector<std::string> errors = validate(params);
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_NE(errors[0].find("~map_file is required unless ~use_map_topic is true"), std::string::npos) << errors[0];
}

TEST(Params, GridConversionParametersAreValidated)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const std::vector<test::ParamCase> cases = {
    { "map_simplify_tolerance", [](Params& p) { p.map_simplify_tolerance = -0.01; }, "(0, 10] m" },
    { "map_simplify_tolerance", [](Params& p) { p.map_simplify_tolerance = 10.5; }, "(0, 10] m" },
    { "map_simplify_tolerance", [nan](Params& p) { p.map_simplify_tolerance = nan; }, "(0, 10] m" },
    { "map_min_area", [nan](Params& p) { p.map_min_area = nan; }, "[0, 1e6] m^2" },
    { "map_min_area", [inf](Params& p) { p.map_min_area = inf; }, "[0, 1e6] m^2" },
    { "map_seed_point", [](Params& p) { p.map_seed_point = { 1.0 }; }, "two finite numbers" },
    { "map_seed_point",
      [](Params& p) {
        p.map_seed_point = { 1.0, 2.0, 3.0 };
      },
      "two finite numbers" },
    { "map_seed_point",
      [inf](Params& p) {
        p.map_seed_point = { 1.0, inf };
      },
      "two finite numbers" },
    { "search_region_seed",
      [](Params& p) {
        p.search_region = "region.yaml";
        p.search_region_seed = { 1.0 };
      },
      "two finite numbers" },
    { "search_region_seed",
      [](Params& p) {
        p.search_region_seed = { 1.0, 2.0 };
      },
      "only with a ~search_region" },
    { "map_occupied_threshold", [](Params& p) { p.map_occupied_threshold = 0; }, "[1, 100]" },
    { "map_occupied_threshold", [](Params& p) { p.map_occupied_threshold = 101; }, "[1, 100]" },
  };
  test::expectEachCaseNamed(cases);
}

TEST(Params, GridConversionLimitsReachTheCoreOptions)
{
  // Limits and the "automatic" values are accepted and reach the core options.
  Params params = validParams();
  params.map_simplify_tolerance = 10.0;
  params.map_min_area = -5.0;
  params.map_seed_point = { 1.5, -2.5 };
  params.map_occupied_threshold = 100;
  EXPECT_TRUE(validate(params).empty());
  core::GridConversionOptions options = toGridOptions(params);
  EXPECT_EQ(options.tolerance, 10.0);
  EXPECT_EQ(options.min_area, -5.0);
  EXPECT_TRUE(options.use_seed);
  EXPECT_EQ(options.seed_point, core::Vec2(1.5, -2.5));
  EXPECT_EQ(options.occupied_threshold, 100);
  params.map_seed_point.clear();
  params.map_occupied_threshold = 1;
  params.map_min_area = 1e6;
  EXPECT_TRUE(validate(params).empty());
  EXPECT_FALSE(toGridOptions(params).use_seed);
  EXPECT_EQ(toGridOptions(params).occupied_threshold, 1);
  // Defaults: one cell, ten cells, the largest region, as the core's defaults.
  const core::GridConversionOptions defaults = toGridOptions(validParams());
  const core::GridConversionOptions core_defaults;
  EXPECT_EQ(defaults.tolerance, core_defaults.tolerance);
  EXPECT_EQ(defaults.min_area, core_defaults.min_area);
  EXPECT_EQ(defaults.use_seed, core_defaults.use_seed);
  EXPECT_EQ(defaults.occupied_threshold, core_defaults.occupied_threshold);
}

TEST(Params, GridMapsWidenTheTolerancesTheUserDidNotSet)
{
  const Params defaults = validParams();
  // A 5 cm grid: one cell of range tolerance, two of agreement.
  Params grid = withGridTolerances(defaults, 0.05);
  EXPECT_DOUBLE_EQ(grid.localizer.range_tolerance, 0.05);
  EXPECT_DOUBLE_EQ(grid.localizer.agreement_tolerance, 0.10);
  // A fine 1 cm grid never goes below the defaults.
  grid = withGridTolerances(defaults, 0.01);
  EXPECT_DOUBLE_EQ(grid.localizer.range_tolerance, defaults.localizer.range_tolerance);
  EXPECT_DOUBLE_EQ(grid.localizer.agreement_tolerance, defaults.localizer.agreement_tolerance);
  // A polygon map (resolution 0) changes nothing.
  grid = withGridTolerances(defaults, 0.0);
  EXPECT_EQ(grid.localizer.range_tolerance, defaults.localizer.range_tolerance);
  EXPECT_EQ(grid.localizer.agreement_tolerance, defaults.localizer.agreement_tolerance);
  // Values the user set are kept, each on its own.
  Params set = validParams();
  set.localizer.range_tolerance = 0.01;
  set.range_tolerance_set = true;
  grid = withGridTolerances(set, 0.1);
  EXPECT_EQ(grid.localizer.range_tolerance, 0.01);
  EXPECT_DOUBLE_EQ(grid.localizer.agreement_tolerance, 0.2);
  set.localizer.agreement_tolerance = 0.03;
  set.agreement_tolerance_set = true;
  grid = withGridTolerances(set, 0.1);
  EXPECT_EQ(grid.localizer.range_tolerance, 0.01);
  EXPECT_EQ(grid.localizer.agreement_tolerance, 0.03);
  // And they reach the core options.
  EXPECT_DOUBLE_EQ(toLocalizerOptions(withGridTolerances(defaults, 0.05)).range_tolerance, 0.05);
}

TEST(Params, DescribeListsTheMapParameters)
{
  const std::string text = describe(validParams());
  for (const char* name :
       { "use_map_topic", "map_simplify_tolerance", "map_min_area", "map_seed_point", "map_occupied_threshold" })
  {
    EXPECT_NE(text.find(name), std::string::npos) << name;
  }
}

}  // namespace
}  // namespace fdml_localization
