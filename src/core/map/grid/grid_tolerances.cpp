#include "fdml_localization/core/map/grid/grid_tolerances.h"

#include "fdml_localization/core/map/polygon_map.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
const char kHeaderKey[] = "fdml: cell_size";
}  // namespace

LocalizerOptions withGridTolerances(const LocalizerOptions& options, double cell_size, const ExplicitTolerances& set)
{
  LocalizerOptions o = options;
  if (!(cell_size > 0.0) || !std::isfinite(cell_size))
  {
    return o;
  }
  if (!set.range_tolerance)
  {
    o.range_tolerance = std::max(o.range_tolerance, cell_size);
  }
  if (!set.agreement_tolerance)
  {
    o.agreement_tolerance = std::max(o.agreement_tolerance, 2.0 * cell_size);
  }
  return o;
}

std::string cellSizeHeader(double cell_size)
{
  char number[64];
  const auto end = std::to_chars(number, number + sizeof(number), cell_size).ptr;  // shortest exact
  return std::string(kHeaderKey) + " " + std::string(number, end);
}

double readCellSizeHeader(std::istream& in, const std::string& source)
{
  std::string line;
  for (int number = 1; std::getline(in, line); ++number)
  {
    const std::size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos)
    {
      continue;
    }
    if (line[first] != '#')
    {
      return 0.0;  // the first vertex: the header is over
    }
    const std::size_t key = line.find(kHeaderKey, first);
    if (key == std::string::npos)
    {
      continue;
    }
    std::istringstream value(line.substr(key + sizeof(kHeaderKey) - 1));
    double cell_size = 0.0;
    std::string rest;
    if (!(value >> cell_size) || (value >> rest) || !(cell_size > 0.0) || !std::isfinite(cell_size))
    {
      throw MapError(source, number, "'" + std::string(kHeaderKey) + "' must be followed by a cell size > 0 [m]");
    }
    return cell_size;
  }
  return 0.0;
}

double readPolyCellSize(const std::string& path)
{
  std::ifstream in(path);
  return in ? readCellSizeHeader(in, path) : 0.0;
}

}  // namespace core
}  // namespace fdml_localization
