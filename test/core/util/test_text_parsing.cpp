// Strict text parsing for tools and files (core/util/text_parsing.h): whole-text numbers, and
// errors that name what was parsed.
#include "fdml_localization/core/util/text_parsing.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace core = fdml_localization::core;

namespace
{
/// The message of the std::invalid_argument @p parse throws; empty when it throws none.
template <typename F>
std::string errorOf(F parse)
{
  try
  {
    parse();
  }
  catch (const std::invalid_argument& e)
  {
    return e.what();
  }
  return std::string();
}
}  // namespace

TEST(TextParsing, NumbersMustBeTheWholeTextAndFinite)
{
  EXPECT_DOUBLE_EQ(core::parseNumber(" 2.5\t", "x"), 2.5);
  EXPECT_EQ(core::parseInteger("-7", "n"), -7);
  for (const char* bad : { "", "2.5m", "nan", "inf", "1e999", "--1" })
  {
    EXPECT_NE(errorOf([&] { core::parseNumber(bad, "--range"); }).find("--range"), std::string::npos) << bad;
  }
  EXPECT_TRUE(std::isinf(core::parseNumber("-inf", "x", true)));
  EXPECT_FALSE(errorOf([] { core::parseInteger("2.5", "--k"); }).empty());
  EXPECT_FALSE(errorOf([] { core::parseInteger("2000000000", "--k"); }).empty());
  double x = 0.0, y = 0.0;
  core::parsePoint("1.5,-2", "--seed-point", x, y);
  EXPECT_DOUBLE_EQ(x, 1.5);
  EXPECT_DOUBLE_EQ(y, -2.0);
  EXPECT_FALSE(errorOf([&] { core::parsePoint("1,2,3", "--seed-point", x, y); }).empty());
}

TEST(TextParsing, SplitScaleTakesTheLastColonsNumber)
{
  EXPECT_EQ(core::splitScale("maps/lab.poly", "--map"), std::make_pair(std::string("maps/lab.poly"), 1.0));
  EXPECT_EQ(core::splitScale("a:b/lab.poly:0.25", "--map"), std::make_pair(std::string("a:b/lab.poly"), 0.25));
  EXPECT_EQ(core::splitScale("70:2", "--random"), std::make_pair(std::string("70"), 2.0));
  for (const char* bad : { "lab.poly:", "lab.poly:x", "lab.poly:0", "lab.poly:-1", "lab.poly:2e6", "lab.poly:inf" })
  {
    EXPECT_NE(errorOf([&] { core::splitScale(bad, "--map"); }).find("--map"), std::string::npos) << bad;
  }
}
