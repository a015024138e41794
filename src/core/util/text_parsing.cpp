#include "fdml_localization/core/util/text_parsing.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
std::string trim(const std::string& text)
{
  const char* blanks = " \t\r\n\f\v";
  const std::size_t begin = text.find_first_not_of(blanks);
  if (begin == std::string::npos)
  {
    return "";
  }
  return text.substr(begin, text.find_last_not_of(blanks) - begin + 1);
}

double parseNumber(const std::string& text, const std::string& what, bool allow_infinite)
{
  const std::string t = trim(text);
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(t.c_str(), &end);
  const bool whole = !t.empty() && end == t.c_str() + t.size();
  if (!whole || std::isnan(value) || (std::isinf(value) && !allow_infinite))
  {
    throw std::invalid_argument(what + ": '" + text + "' is not a " + (allow_infinite ? "number" : "finite number"));
  }
  return value;
}

int parseInteger(const std::string& text, const std::string& what)
{
  const std::string t = trim(text);
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(t.c_str(), &end, 10);
  if (t.empty() || end != t.c_str() + t.size() || errno == ERANGE || value < -1000000000L || value > 1000000000L)
  {
    throw std::invalid_argument(what + ": '" + text + "' is not an integer");
  }
  return static_cast<int>(value);
}

void parsePoint(const std::string& text, const std::string& what, double& x, double& y)
{
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos)
  {
    throw std::invalid_argument(what + ": expected X,Y, got '" + text + "'");
  }
  x = parseNumber(text.substr(0, comma), what);
  y = parseNumber(text.substr(comma + 1), what);
}

std::pair<std::string, double> splitScale(const std::string& text, const std::string& what)
{
  const std::size_t colon = text.rfind(':');
  if (colon == std::string::npos)
  {
    return { text, 1.0 };
  }
  const std::string scale_text = text.substr(colon + 1);
  const double scale = parseNumber(scale_text, what + " scale");
  if (!(scale > 0.0) || scale > 1e6)
  {
    throw std::invalid_argument(what + ": scale " + scale_text + " must be in (0, 1e6]");
  }
  return { text.substr(0, colon), scale };
}

}  // namespace core
}  // namespace fdml_localization
