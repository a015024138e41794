// Helpers shared by the localizer parameter tests.
#pragma once

#include "fdml_localization/ros/params.h"

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
}  // namespace test
}  // namespace fdml_localization
