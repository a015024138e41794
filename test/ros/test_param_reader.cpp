// The node's parameters read from an in-memory parameter tree (no roscore): typed reads
// (ParamReader), and a parameter fuzz: a value of a wrong type, or out of range, for every
// parameter is an error naming that parameter.
#include "fdml_localization/ros/param_utils.h"
#include "params_test_utils.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace fdml_localization
{
namespace
{
using core::ParamValue;
using test::errorsNaming;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

ParamValue numbers(const std::vector<double>& values)
{
  ParamValue list = ParamValue::makeList();
  for (double v : values)
  {
    list.append(ParamValue::fromDouble(v));
  }
  return list;
}

/// A tree with a good map and @p name set to @p value.
ParamValue treeWith(const std::string& name, const ParamValue& value)
{
  ParamValue tree = ParamValue::makeMap();
  tree.set("map_file", ParamValue::fromString("package://fdml_localization/maps/square_room.poly"));
  tree.set(name, value);
  return tree;
}

std::vector<std::string> errorsFor(const ParamValue& tree)
{
  return validate(paramsFromTree(tree, "/ros_home", "/home/u"));
}

enum class Kind
{
  Bool,
  Int,
  Number,
  String,
  Numbers
};

/// Every parameter of the node and its type.
const std::vector<std::pair<std::string, Kind>>& everyParameter()
{
  static const std::vector<std::pair<std::string, Kind>> parameters = {
    { "map_file", Kind::String },
    { "use_map_topic", Kind::Bool },
    { "map_simplify_tolerance", Kind::Number },
    { "map_min_area", Kind::Number },
    { "map_seed_point", Kind::Numbers },
    { "map_occupied_threshold", Kind::Int },
    { "search_region", Kind::String },
    { "search_region_seed", Kind::Numbers },
    { "measurements_per_batch", Kind::Int },
    { "batch_stride", Kind::Int },
    { "mode", Kind::String },
    { "beams_per_scan", Kind::Int },
    { "transform_tolerance", Kind::Number },
    { "future_tolerance", Kind::Number },
    { "max_sensor_frames", Kind::Int },
    { "relocalize_timeout", Kind::Number },
    { "publish_tf", Kind::Bool },
    { "tf_publish_rate", Kind::Number },
    { "global_frame_id", Kind::String },
    { "odom_frame_id", Kind::String },
    { "base_frame_id", Kind::String },
    { "range_topic", Kind::String },
    { "scan_topic", Kind::String },
    { "engine", Kind::String },
    { "method", Kind::String },
    { "resolution", Kind::Int },
    { "theta_resolution", Kind::Int },
    { "min_inliers", Kind::Int },
    { "agreement_tolerance", Kind::Number },
    { "uniqueness_distance", Kind::Number },
    { "uniqueness_angle", Kind::Number },
    { "range_tolerance", Kind::Number },
    { "max_candidates", Kind::Int },
    { "threads", Kind::Int },
    { "max_boxes", Kind::Int },
    { "deadline", Kind::Number },
    { "cache_dir", Kind::String },
  };
  return parameters;
}

const char* expectedType(Kind kind)
{
  switch (kind)
  {
    case Kind::Bool:
      return "expected a boolean";
    case Kind::Int:
      return "expected an integer";
    case Kind::Number:
      return "expected a number";
    case Kind::String:
      return "expected a string";
    case Kind::Numbers:
      return "expected a list of numbers";
  }
  return "?";
}

bool accepts(Kind kind, const ParamValue& value)
{
  switch (kind)
  {
    case Kind::Bool:
      return value.type() == ParamValue::Type::Bool;
    case Kind::Int:
      return value.type() == ParamValue::Type::Int;
    case Kind::Number:
      return value.isNumber();
    case Kind::String:
      return value.type() == ParamValue::Type::String;
    case Kind::Numbers:
      return value.isList();
  }
  return false;
}

TEST(ParamReader, WrongTypesAreErrorsNamingTheParameterAndTheType)
{
  ParamValue map = ParamValue::makeMap();
  map.set("a", ParamValue::fromInt(1));
  const std::vector<ParamValue> values = {
    ParamValue::fromBool(true),    ParamValue::fromInt(3), ParamValue::fromDouble(2.5),
    ParamValue::fromString("abc"), numbers({ 1.0, 2.0 }),  map,
  };
  for (const auto& parameter : everyParameter())
  {
    for (const ParamValue& value : values)
    {
      if (accepts(parameter.second, value))
      {
        continue;
      }
      const std::vector<std::string> errors = errorsFor(treeWith(parameter.first, value));
      const std::string expected = "~" + parameter.first + ": " + expectedType(parameter.second);
      bool found = false;
      for (const std::string& error : errors)
      {
        found = found || error.rfind(expected, 0) == 0;
      }
      EXPECT_TRUE(found) << parameter.first << " set to " << ParamValue::typeName(value.type()) << ": "
                         << (errors.empty() ? "no error" : errors[0]);
    }
  }
}

TEST(ParamReader, TheIssuesExamples)
{
  std::vector<std::string> errors = errorsFor(treeWith("resolution", ParamValue::fromString("abc")));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], "~resolution: expected an integer in [-2147483648, 2147483647], got a string (\"abc\")");
  errors = errorsFor(treeWith("mode", ParamValue::fromInt(3)));
  ASSERT_EQ(errors.size(), 1u);
  EXPECT_EQ(errors[0], "~mode: expected a string, got an integer (3)");
}

TEST(ParamReader, IntegersAreRangeCheckedBeforeConversion)
{
  // Integral numbers are integers; fractions, NaN and values beyond int are not.
  Params p = paramsFromTree(treeWith("resolution", ParamValue::fromDouble(64.0)), "", "/home/u");
  EXPECT_TRUE(p.type_errors.empty());
  EXPECT_EQ(p.localizer.resolution, 64);
  for (double bad : { 64.5, kNan, kInf, 3e9, -3e9 })
  {
    p = paramsFromTree(treeWith("resolution", ParamValue::fromDouble(bad)), "", "/home/u");
    ASSERT_EQ(p.type_errors.size(), 1u) << bad;
    EXPECT_EQ(p.type_errors[0].rfind("~resolution: expected an integer", 0), 0u) << p.type_errors[0];
    EXPECT_EQ(p.localizer.resolution, core::LocalizerOptions().resolution);  // the default is kept
  }
  p = paramsFromTree(treeWith("threads", ParamValue::fromInt(std::int64_t(1) << 40)), "", "/home/u");
  EXPECT_EQ(p.type_errors.size(), 1u);
  // A long takes what an int cannot.
  p = paramsFromTree(treeWith("max_boxes", ParamValue::fromInt(std::int64_t(1) << 40)), "", "/home/u");
  EXPECT_TRUE(p.type_errors.empty());
  EXPECT_EQ(p.localizer.max_boxes, std::int64_t(1) << 40);
}

TEST(ParamReader, ValuesOfTheRightTypeAreRead)
{
  ParamValue tree = treeWith("mode", ParamValue::fromString("continuous"));
  tree.set("resolution", ParamValue::fromInt(64));
  tree.set("agreement_tolerance", ParamValue::fromInt(1));  // an integer is a number
  tree.set("publish_tf", ParamValue::fromBool(true));
  tree.set("map_seed_point", numbers({ 1.5, -2.5 }));
  tree.set("base_frame_id", ParamValue::fromString("/base"));
  tree.set("cache_dir", ParamValue::fromString("~/cache"));
  tree.set("future_tolerance", ParamValue::fromDouble(2.0));
  tree.set("max_sensor_frames", ParamValue::fromInt(50));
  const Params p = paramsFromTree(tree, "", "/home/u");
  EXPECT_TRUE(validate(p).empty()) << validate(p)[0];
  EXPECT_EQ(p.mode, "continuous");
  EXPECT_EQ(p.localizer.resolution, 64);
  EXPECT_EQ(p.localizer.agreement_tolerance, 1.0);
  EXPECT_TRUE(p.agreement_tolerance_set);
  EXPECT_FALSE(p.range_tolerance_set);
  EXPECT_TRUE(p.publish_tf);
  EXPECT_EQ(p.map_seed_point, std::vector<double>({ 1.5, -2.5 }));
  EXPECT_EQ(p.base_frame_id, "base");  // as tf2 expects
  EXPECT_EQ(p.localizer.cache_dir, "/home/u/cache");
  EXPECT_EQ(p.future_tolerance, 2.0);
  EXPECT_EQ(p.max_sensor_frames, 50);
  // Defaults: the cache under ROS_HOME, else HOME.
  EXPECT_EQ(paramsFromTree(ParamValue::makeMap(), "/rh", "/home/u").localizer.cache_dir, "/rh/fdml_localization");
  EXPECT_EQ(paramsFromTree(ParamValue(), "", "/home/u").localizer.cache_dir, "/home/u/.ros/fdml_localization");
}

TEST(ParamReader, OutOfRangeValuesOfEveryParameterNameIt)
{
  const std::vector<std::pair<std::string, std::vector<ParamValue>>> cases = {
    { "map_simplify_tolerance",
      { ParamValue::fromDouble(-0.01), ParamValue::fromInt(11), ParamValue::fromDouble(kNan) } },
    { "map_min_area", { ParamValue::fromDouble(kNan), ParamValue::fromDouble(kInf), ParamValue::fromDouble(1e7) } },
    { "map_seed_point", { numbers({ 1.0 }), numbers({ 1.0, 2.0, 3.0 }), numbers({ 1.0, kInf }) } },
    { "map_occupied_threshold", { ParamValue::fromInt(0), ParamValue::fromInt(101) } },
    { "measurements_per_batch", { ParamValue::fromInt(2), ParamValue::fromInt(256), ParamValue::fromDouble(1e10) } },
    { "batch_stride", { ParamValue::fromInt(0), ParamValue::fromInt(11) } },
    { "mode", { ParamValue::fromString("sometimes"), ParamValue::fromString("") } },
    { "beams_per_scan", { ParamValue::fromInt(0), ParamValue::fromInt(1001) } },
    { "transform_tolerance", { ParamValue::fromDouble(-0.1), ParamValue::fromInt(11), ParamValue::fromDouble(kNan) } },
    { "future_tolerance", { ParamValue::fromDouble(-1.0), ParamValue::fromInt(3601), ParamValue::fromDouble(kInf) } },
    { "max_sensor_frames", { ParamValue::fromInt(0), ParamValue::fromInt(1000001) } },
    { "relocalize_timeout", { ParamValue::fromInt(0), ParamValue::fromInt(3601), ParamValue::fromDouble(kNan) } },
    { "tf_publish_rate", { ParamValue::fromInt(0), ParamValue::fromDouble(1e300) } },
    { "global_frame_id", { ParamValue::fromString(""), ParamValue::fromString("a b") } },
    { "odom_frame_id", { ParamValue::fromString("/"), ParamValue::fromString("base_link") } },
    { "base_frame_id", { ParamValue::fromString(""), ParamValue::fromString("x\ty") } },
    { "range_topic", { ParamValue::fromString("") } },
    { "scan_topic", { ParamValue::fromString("") } },
    { "engine", { ParamValue::fromString("quantum") } },
    { "method", { ParamValue::fromString("magic") } },
    { "resolution", { ParamValue::fromInt(15), ParamValue::fromInt(100001), ParamValue::fromInt(-1) } },
    { "theta_resolution", { ParamValue::fromInt(15), ParamValue::fromInt(100001), ParamValue::fromInt(-5) } },
    { "min_inliers", { ParamValue::fromInt(2), ParamValue::fromInt(11), ParamValue::fromInt(-1) } },
    { "agreement_tolerance", { ParamValue::fromInt(0), ParamValue::fromDouble(-1.0), ParamValue::fromDouble(kNan) } },
    { "uniqueness_distance", { ParamValue::fromDouble(-1.0), ParamValue::fromInt(101) } },
    { "uniqueness_angle", { ParamValue::fromDouble(-1.0), ParamValue::fromInt(4) } },
    { "range_tolerance", { ParamValue::fromDouble(-0.01), ParamValue::fromInt(11), ParamValue::fromDouble(kInf) } },
    { "max_candidates", { ParamValue::fromInt(0), ParamValue::fromInt(1000001) } },
    { "threads", { ParamValue::fromInt(-1), ParamValue::fromInt(1025) } },
    { "max_boxes", { ParamValue::fromInt(999), ParamValue::fromInt(-1) } },
    { "deadline", { ParamValue::fromDouble(-1.0), ParamValue::fromInt(3601), ParamValue::fromDouble(kNan) } },
  };
  for (const auto& c : cases)
  {
    for (const ParamValue& value : c.second)
    {
      const std::vector<std::string> errors = errorsFor(treeWith(c.first, value));
      EXPECT_FALSE(errorsNaming(errors, c.first).empty())
          << c.first << ": " << (errors.empty() ? "accepted" : "only: " + errors[0]);
    }
  }
  // The map file is required, unless the map comes from the topic.
  EXPECT_FALSE(errorsNaming(errorsFor(treeWith("map_file", ParamValue::fromString(""))), "map_file").empty());
}

/// A random value: any type, with NaN, infinities, huge and boundary numbers.
ParamValue randomValue(std::mt19937& rng)
{
  const double specials[] = { kNan, kInf, -kInf, 0.0, -1.0, 1e300, -1e300, 0.5, 3.0, 16.0, 1024.0, 1e6, 2147483648.0 };
  const char* strings[] = { "", "abc", "continuous", "voxel", "adaptive", "paper", "/x", " ", "base_link" };
  std::uniform_int_distribution<int> pick(0, 12);
  switch (std::uniform_int_distribution<int>(0, 5)(rng))
  {
    case 0:
      return ParamValue::fromBool(pick(rng) % 2 == 0);
    case 1:
      return ParamValue::fromInt(std::uniform_int_distribution<std::int64_t>(-5, 2000)(rng));
    case 2:
      return ParamValue::fromDouble(specials[pick(rng)]);
    case 3:
      return ParamValue::fromString(strings[pick(rng) % 9]);
    case 4:
      return numbers({ specials[pick(rng)], specials[pick(rng)] });
    default:
      return ParamValue::makeMap();
  }
}

TEST(ParamReader, RandomParameterSetsAreAcceptedOnlyWhenTheCoreAgrees)
{
  std::mt19937 rng(15);
  const auto& parameters = everyParameter();
  for (int trial = 0; trial < 2000; ++trial)
  {
    ParamValue tree = treeWith("mode", ParamValue::fromString("on_request"));
    const int count = std::uniform_int_distribution<int>(1, 4)(rng);
    for (int i = 0; i < count; ++i)
    {
      tree.set(parameters[rng() % parameters.size()].first, randomValue(rng));
    }
    const Params p = paramsFromTree(tree, "", "/home/u");
    const std::vector<std::string> errors = validate(p);
    for (const std::string& error : errors)
    {
      bool named = false;
      for (const auto& parameter : parameters)
      {
        named = named || !errorsNaming({ error }, parameter.first).empty();
      }
      EXPECT_TRUE(named) << "trial " << trial << ": an error naming no parameter: " << error;
    }
    if (errors.empty())
    {
      EXPECT_TRUE(core::validate(toLocalizerOptions(p)).empty()) << "trial " << trial;
    }
  }
}

}  // namespace
}  // namespace fdml_localization
