#include "readings_csv.h"

#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/util/file_checks.h"
#include "fdml_localization/core/util/text_parsing.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace tools
{
namespace
{
std::vector<std::string> splitCsv(const std::string& line)
{
  std::vector<std::string> fields;
  std::stringstream in(line);
  std::string field;
  while (std::getline(in, field, ','))
  {
    fields.push_back(core::trim(field));
  }
  if (!line.empty() && line.back() == ',')
  {
    fields.push_back("");
  }
  return fields;
}

/// The columns after "gx,gy,gtheta,d": optionally max_range, then optionally fov.
struct CsvColumns
{
  bool max_range = false;
  bool fov = false;
};

CsvColumns readHeader(const std::string& where, const std::string& text)
{
  const std::string base = "gx,gy,gtheta,d";
  for (const bool max_range : { false, true })
  {
    for (const bool fov : { false, true })
    {
      if (text == base + (max_range ? ",max_range" : "") + (fov ? ",fov" : ""))
      {
        return { max_range, fov };
      }
    }
  }
  throw InputError(where +
                   ": expected the header 'gx,gy,gtheta,d' (optionally ',max_range', then optionally ',fov'), got '" +
                   text + "'");
}

/// The fov column: the sensor's full field of view [deg] in [0, 180] (0 = a ray); returns the
/// reading's cone half-angle [rad].
double parseFovColumn(const std::string& field, const std::string& where)
{
  const double degrees = core::parseNumber(field, where + ": fov", true);
  if (!(degrees >= 0.0 && degrees <= 180.0))
  {
    throw InputError(where + ": fov must be in [0, 180] degrees (the full field of view; 0 = a ray), got " + field);
  }
  return std::min(0.5 * degrees * core::kPi / 180.0, core::kMaxConeHalfAngle);
}

core::Reading parseReading(const std::string& where, const std::string& text, const CsvColumns& columns,
                           double default_max_range)
{
  const std::vector<std::string> fields = splitCsv(text);
  const std::size_t expected = 4 + (columns.max_range ? 1 : 0) + (columns.fov ? 1 : 0);
  if (fields.size() != expected)
  {
    throw InputError(where + ": expected " + std::to_string(expected) + " fields, got " +
                     std::to_string(fields.size()));
  }
  core::Reading r;
  r.offset.x = core::parseNumber(fields[0], where + ": gx", true);
  r.offset.y = core::parseNumber(fields[1], where + ": gy", true);
  r.offset.theta = core::parseNumber(fields[2], where + ": gtheta", true);
  r.range = core::parseNumber(fields[3], where + ": d", true);
  r.max_range = columns.max_range ? core::parseNumber(fields[4], where + ": max_range", true) : default_max_range;
  r.half_angle = columns.fov ? parseFovColumn(fields.back(), where) : 0.0;
  if (!std::isfinite(r.offset.x) || !std::isfinite(r.offset.y) || !std::isfinite(r.offset.theta))
  {
    throw InputError(where + ": gx, gy and gtheta must be finite");
  }
  if (std::isnan(r.range) || r.range < 0.0)
  {
    throw InputError(where + ": d must be >= 0 or inf, got " + fields[3]);
  }
  if (std::isinf(r.range) && !std::isfinite(r.max_range))
  {
    throw InputError(where + ": d = inf needs a finite max range (--max-range or a max_range column)");
  }
  return r;
}

}  // namespace

CsvReadings readReadingsCsv(const std::string& path, double default_max_range)
{
  const std::string problem = core::regularFileProblem(path);
  std::ifstream in;
  if (problem.empty())
  {
    in.open(path);
  }
  if (!problem.empty() || !in)
  {
    throw InputError(path + ": cannot open the readings file" + (problem.empty() ? "" : ": " + problem));
  }
  std::string line;
  int line_no = 0;
  bool have_header = false;
  CsvColumns columns;
  CsvReadings csv;
  while (std::getline(in, line))
  {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    if (line.find('\0') != std::string::npos)
    {
      throw InputError(where + ": NUL byte in the line (not a text file?)");
    }
    const std::string t = core::trim(line);
    if (t.empty() || t[0] == '#')
    {
      continue;
    }
    if (!have_header)
    {
      columns = readHeader(where, t);
      have_header = true;
      continue;
    }
    csv.readings.push_back(parseReading(where, t, columns, default_max_range));
    csv.lines.push_back(line_no);
  }
  if (!have_header)
  {
    throw InputError(path + ": empty file (expected the header 'gx,gy,gtheta,d')");
  }
  return csv;
}

void validateCsvReadings(const CsvReadings& csv, const std::string& path, const core::LocalizerOptions& options)
{
  try
  {
    core::validateReadings(csv.readings, options);
  }
  catch (const core::InvalidInput& e)
  {
    const std::string what = e.what();
    const std::string prefix = "reading ";
    const std::size_t colon = what.find(": ");
    if (what.rfind(prefix, 0) == 0 && colon != std::string::npos && colon > prefix.size() &&
        what.find_first_not_of("0123456789", prefix.size()) == colon)
    {
      const std::size_t index = std::stoul(what.substr(prefix.size(), colon - prefix.size()));
      if (index < csv.lines.size())
      {
        throw InputError(path + ":" + std::to_string(csv.lines[index]) + what.substr(colon));
      }
    }
    throw InputError(path + ": " + what);
  }
}

}  // namespace tools
}  // namespace fdml_localization
