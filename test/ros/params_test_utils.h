// Helpers shared by the localizer parameter tests.
#pragma once

#include "fdml_localization/ros/params.h"

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace test
{
/// The defaults with a map: valid.
inline Params validParams()
{
  Params params;
  params.map_file = "package://fdml_localization/maps/square_room.poly";
  return params;
}

/// The errors mentioning "~name" followed by a space or a colon.
inline std::vector<std::string> errorsNaming(const std::vector<std::string>& errors, const std::string& name)
{
  std::vector<std::string> out;
  for (const std::string& error : errors)
  {
    if (error.find("~" + name + " ") != std::string::npos || error.find("~" + name + ":") != std::string::npos)
    {
      out.push_back(error);
    }
  }
  return out;
}

/// A parameter set out of range: its name, how to set it, and the allowed range its error names.
struct ParamCase
{
  const char* name;
  std::function<void(Params&)> set;
  const char* range;
};

/// Each case, applied alone to validParams(), gives exactly one error naming it and its range.
inline void expectEachCaseNamed(const std::vector<ParamCase>& cases)
{
  for (const ParamCase& c : cases)
  {
    Params params = validParams();
    c.set(params);
    const std::vector<std::string> errors = validate(params);
    ASSERT_EQ(errors.size(), 1u) << c.name << ": " << (errors.empty() ? "" : errors[0]);
    EXPECT_EQ(errorsNaming(errors, c.name).size(), 1u) << errors[0];
    EXPECT_NE(errors[0].find(c.range), std::string::npos) << errors[0];
  }
}
}  // namespace test
}  // namespace fdml_localization
