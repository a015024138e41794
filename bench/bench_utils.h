// Small helpers shared by the Google Benchmark sources.
#pragma once

#include <sys/resource.h>

#include <sstream>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace bench
{
/// The non-empty parts of @p text between @p sep characters (environment-variable lists).
inline std::vector<std::string> split(const std::string& text, char sep)
{
  std::vector<std::string> parts;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, sep))
  {
    if (!part.empty())
    {
      parts.push_back(part);
    }
  }
  return parts;
}

/// The process's peak resident memory so far [MB].
inline double peakRssMb()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

}  // namespace bench
}  // namespace fdml_localization
