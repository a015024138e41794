/**
 * @file in_out_arguments.h
 * @brief The command line of the map tools, "TOOL [OPTIONS] IN OUT": --help prints the usage and
 *        exits 0; other arguments starting with '-' are options, each taking its value through
 *        the getter; exactly two positionals. Errors are std::invalid_argument (exit 2).
 */
#pragma once

#include <cstdlib>
#include <functional>
#include <iostream>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace tools
{
/// Applies one option (@p flag, its value through the getter); false when it is not an option.
using FlagApplier = std::function<bool(const std::string& flag, const std::function<std::string()>& value)>;

/**
 * @param need the message when the positionals are missing (e.g. "need MAP.yaml and OUT.poly")
 * @throws std::invalid_argument for an unknown option, a missing value or a wrong positional count
 */
inline void parseInOutArguments(int argc, char** argv, const char* usage, const FlagApplier& apply, std::string* input,
                                std::string* output, const std::string& need)
{
  int positional = 0;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
      {
        throw std::invalid_argument(arg + " needs a value");
      }
      return argv[++i];
    };
    if (arg == "-h" || arg == "--help")
    {
      std::cout << usage;
      std::exit(0);
    }
    if (apply(arg, value))
    {
      continue;
    }
    if (!arg.empty() && arg[0] == '-')
    {
      throw std::invalid_argument("unknown option " + arg);
    }
    if (positional >= 2)
    {
      throw std::invalid_argument("too many arguments ('" + arg + "')");
    }
    *(positional++ == 0 ? input : output) = arg;
  }
  if (positional != 2)
  {
    throw std::invalid_argument(need);
  }
}

}  // namespace tools
}  // namespace fdml_localization
