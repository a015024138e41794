#include "fdml_localization/core/map/map_io.h"

#include "fdml_localization/core/util/file_checks.h"
#include "fdml_localization/core/util/text_parsing.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{

/// Parses "x y" exactly (two numbers, nothing else). Returns false with a reason otherwise.
bool parseVertex(const std::string& text, Vec2& out, std::string& reason)
{
  const char* p = text.c_str();
  double values[2];
  for (double& value : values)
  {
    while (*p == ' ' || *p == '\t' || *p == ',')
    {
      ++p;
    }
    char* end = nullptr;
    errno = 0;
    value = std::strtod(p, &end);
    if (end == p)
    {
      reason = "expected two numbers \"x y\", got \"" + text + "\"";
      return false;
    }
    if (!std::isfinite(value) || errno == ERANGE)
    {
      reason = "non-finite coordinate in \"" + text + "\"";
      return false;
    }
    if (std::abs(value) > kMaxMapCoordinate)
    {
      reason = "coordinate beyond +-1e9 m (the largest a map may use) in \"" + text + "\"";
      return false;
    }
    p = end;
  }
  while (*p == ' ' || *p == '\t' || *p == '\r')
  {
    ++p;
  }
  if (*p != '\0')
  {
    reason = "unexpected text after \"x y\": \"" + std::string(p) + "\"";
    return false;
  }
  out = Vec2(values[0], values[1]);
  return true;
}
}  // namespace

PolygonMap parsePoly(std::istream& in, const std::string& source)
{
  std::vector<Ring> rings(1);
  std::vector<std::vector<int>> lines(1);  // source line of every vertex
  std::string raw;
  int line_no = 0;
  while (std::getline(in, raw))
  {
    ++line_no;
    if (raw.find('\0') != std::string::npos)
    {
      throw MapError(source, line_no, "NUL byte in the line (not a text file?)");
    }
    const std::size_t hash = raw.find('#');
    const bool comment_only = hash != std::string::npos && trim(raw.substr(0, hash)).empty();
    const std::string text = trim(hash == std::string::npos ? raw : raw.substr(0, hash));
    if (text.empty())
    {
      if (!comment_only && !rings.back().empty())
      {
        rings.emplace_back();
        lines.emplace_back();
      }
      continue;
    }
    Vec2 vertex;
    std::string reason;
    if (!parseVertex(text, vertex, reason))
    {
      throw MapError(source, line_no, reason);
    }
    rings.back().push_back(vertex);
    lines.back().push_back(line_no);
  }
  if (rings.back().empty())
  {
    rings.pop_back();
    lines.pop_back();
  }
  if (rings.empty())
  {
    throw MapError(source, std::max(line_no, 1), "no vertices: the map is empty");
  }
  const std::vector<RingIssue> issues = validateRings(rings);
  if (!issues.empty())
  {
    const RingIssue& issue = issues.front();
    const std::vector<int>& ring_lines = lines[issue.ring];
    const int line = ring_lines[std::min(issue.vertex, ring_lines.size() - 1)];
    const std::string what = issue.ring == 0 ? "outer boundary" : "hole " + std::to_string(issue.ring);
    throw MapError(source, line,
                   what + " (ring starting at line " + std::to_string(ring_lines.front()) + "): " + issue.reason);
  }
  return PolygonMap::fromRings(std::move(rings), source);
}

PolygonMap loadPolyFile(const std::string& path)
{
  const std::string problem = regularFileProblem(path);
  if (!problem.empty())
  {
    throw MapError(path, 0, "cannot open map file: " + problem);
  }
  std::ifstream in(path);
  if (!in)
  {
    throw MapError(path, 0, std::string("cannot open map file: ") + std::strerror(errno));
  }
  return parsePoly(in, path);
}

void writePoly(std::ostream& out, const PolygonMap& map, const std::string& comment)
{
  if (!comment.empty())
  {
    std::istringstream lines(comment);
    std::string line;
    while (std::getline(lines, line))
    {
      out << "# " << line << "\n";
    }
  }
  out << std::setprecision(17);
  for (std::size_t r = 0; r < map.rings().size(); ++r)
  {
    if (r > 0)
    {
      out << "\n";
    }
    for (const Vec2& v : map.rings()[r])
    {
      out << v.x() << " " << v.y() << "\n";
    }
  }
}

void savePolyFile(const std::string& path, const PolygonMap& map, const std::string& comment)
{
  std::ofstream out(path);
  if (!out)
  {
    throw std::runtime_error(path + ": cannot write map file: " + std::strerror(errno));
  }
  writePoly(out, map, comment);
  if (!out)
  {
    throw std::runtime_error(path + ": error while writing map file");
  }
}

}  // namespace core
}  // namespace fdml_localization
