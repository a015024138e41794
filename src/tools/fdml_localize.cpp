// fdml_localize: global localization from a CSV of range readings on a .poly map.
// Usage: kUsage below (fdml_localize --help).
// READINGS.csv: header "gx,gy,gtheta,d" (optionally ",max_range"), one reading per line
// [m, rad]; d may be "inf" (no return within max_range). Prints "rank,x,y,theta,inliers,rms"
// and one candidate per line, best first; exit 0 (also with no candidate), 2 on bad input.
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/util/file_checks.h"
#include "fdml_localization/core/util/text_parsing.h"

#include <cerrno>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <sstream>
#include <string>
#include <vector>

namespace
{
namespace core = fdml_localization::core;

/// Bad input: reported on stderr, exit code 2.
struct UsageError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

const char* kUsage = "usage: fdml_localize --map MAP [--resolution N] [--min-inliers K|auto]\n"
                     "                     [--method robust|paper|baseline] [--range-tolerance T] [--tolerance EPS]\n"
                     "                     [--threads J] [--engine voxel|adaptive] [--cache-dir DIR]\n"
                     "                     [--theta-resolution N] [--max-candidates M] [--max-range R] [--verbose]\n"
                     "                     READINGS.csv\n";

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

/// The readings of a CSV file, each with the line it came from.
struct CsvReadings
{
  std::vector<core::Reading> readings;
  std::vector<int> lines;
};

/// Reads the header line; returns whether it has the max_range column.
bool readHeader(const std::string& where, const std::string& text)
{
  if (text == "gx,gy,gtheta,d")
  {
    return false;
  }
  if (text == "gx,gy,gtheta,d,max_range")
  {
    return true;
  }
  throw UsageError(where + ": expected the header 'gx,gy,gtheta,d' (optionally ',max_range'), got '" + text + "'");
}

core::Reading parseReading(const std::string& where, const std::string& text, bool has_max_range,
                           double default_max_range)
{
  const std::vector<std::string> fields = splitCsv(text);
  const std::size_t expected = has_max_range ? 5 : 4;
  if (fields.size() != expected)
  {
    throw UsageError(where + ": expected " + std::to_string(expected) + " fields, got " +
                     std::to_string(fields.size()));
  }
  core::Reading r;
  r.offset.x = core::parseNumber(fields[0], where + ": gx", true);
  r.offset.y = core::parseNumber(fields[1], where + ": gy", true);
  r.offset.theta = core::parseNumber(fields[2], where + ": gtheta", true);
  r.range = core::parseNumber(fields[3], where + ": d", true);
  r.max_range = has_max_range ? core::parseNumber(fields[4], where + ": max_range", true) : default_max_range;
  if (!std::isfinite(r.offset.x) || !std::isfinite(r.offset.y) || !std::isfinite(r.offset.theta))
  {
    throw UsageError(where + ": gx, gy and gtheta must be finite");
  }
  if (std::isnan(r.range) || r.range < 0.0)
  {
    throw UsageError(where + ": d must be >= 0 or inf, got " + fields[3]);
  }
  if (std::isinf(r.range) && !std::isfinite(r.max_range))
  {
    throw UsageError(where + ": d = inf needs a finite max range (--max-range or a max_range column)");
  }
  return r;
}

CsvReadings readCsv(const std::string& path, double default_max_range)
{
  const std::string problem = core::regularFileProblem(path);
  std::ifstream in;
  if (problem.empty())
  {
    in.open(path);
  }
  if (!problem.empty() || !in)
  {
    throw UsageError(path + ": cannot open the readings file" + (problem.empty() ? "" : ": " + problem));
  }
  std::string line;
  int line_no = 0;
  bool have_header = false;
  bool has_max_range = false;
  CsvReadings csv;
  while (std::getline(in, line))
  {
    ++line_no;
    const std::string where = path + ":" + std::to_string(line_no);
    if (line.find('\0') != std::string::npos)
    {
      throw UsageError(where + ": NUL byte in the line (not a text file?)");
    }
    const std::string t = core::trim(line);
    if (t.empty() || t[0] == '#')
    {
      continue;
    }
    if (!have_header)
    {
      has_max_range = readHeader(where, t);
      have_header = true;
      continue;
    }
    csv.readings.push_back(parseReading(where, t, has_max_range, default_max_range));
    csv.lines.push_back(line_no);
  }
  if (!have_header)
  {
    throw UsageError(path + ": empty file (expected the header 'gx,gy,gtheta,d')");
  }
  return csv;
}

/// The core's check of the batch, its errors naming the file and line ("reading N: ..." from
/// core::validateReadings becomes "FILE:LINE: ...").
void validateCsv(const CsvReadings& csv, const std::string& path, const core::LocalizerOptions& options)
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
        throw UsageError(path + ":" + std::to_string(csv.lines[index]) + what.substr(colon));
      }
    }
    throw UsageError(path + ": " + what);
  }
}

struct Arguments
{
  std::string map;
  std::string csv;
  core::LocalizerOptions options;
  double max_range = core::kInf;
  bool verbose = false;
};

/// Applies one option flag that takes a value; false when @p flag is not one of them.
bool applyValueFlag(const std::string& flag, const std::function<std::string()>& value, Arguments& args)
{
  core::LocalizerOptions& o = args.options;
  if (flag == "--map")
  {
    args.map = value();
  }
  else if (flag == "--resolution" || flag == "--theta-resolution" || flag == "--threads" || flag == "--max-candidates")
  {
    const int n = core::parseInteger(value(), flag);
    int& target = flag == "--resolution"       ? o.resolution :
                  flag == "--theta-resolution" ? o.theta_resolution :
                  flag == "--threads"          ? o.threads :
                                                 o.max_candidates;
    target = n;
  }
  else if (flag == "--min-inliers")
  {
    const std::string v = value();
    o.min_inliers = v == "auto" ? 0 : core::parseInteger(v, flag);
    if (v != "auto" && o.min_inliers < 3)
    {
      throw UsageError("--min-inliers " + v + ": must be 'auto' or an integer >= 3");
    }
  }
  else if (flag == "--method")
  {
    o.method = core::parseMethod(value());
  }
  else if (flag == "--engine")
  {
    o.engine = core::parseEngine(value());
  }
  else if (flag == "--range-tolerance")
  {
    o.range_tolerance = core::parseNumber(value(), flag);
  }
  else if (flag == "--tolerance")
  {
    o.agreement_tolerance = core::parseNumber(value(), flag);
  }
  else if (flag == "--cache-dir")
  {
    o.cache_dir = value();
  }
  else if (flag == "--max-range")
  {
    args.max_range = core::parseNumber(value(), flag, true);
  }
  else
  {
    return false;
  }
  return true;
}

Arguments parseArguments(int argc, char** argv)
{
  Arguments args;
  for (int i = 1; i < argc; ++i)
  {
    const std::string flag = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
      {
        throw UsageError(flag + " needs a value");
      }
      return argv[++i];
    };
    if (applyValueFlag(flag, value, args))
    {
      continue;
    }
    if (flag == "--verbose")
    {
      args.verbose = true;
    }
    else if (flag == "--help" || flag == "-h")
    {
      std::cout << kUsage;
      std::exit(0);
    }
    else if (!flag.empty() && flag[0] == '-' && flag != "-")
    {
      throw UsageError("unknown option " + flag);
    }
    else if (args.csv.empty())
    {
      args.csv = flag;
    }
    else
    {
      throw UsageError("more than one readings file: " + args.csv + " and " + flag);
    }
  }
  if (args.map.empty())
  {
    throw UsageError("--map MAP is required");
  }
  if (args.csv.empty())
  {
    throw UsageError("the readings file READINGS.csv is required");
  }
  return args;
}

/// One row per candidate; `unambiguous` is 1 on the best row when core::isUnambiguous() holds.
/// The command-line flag of a core option (core::validate() names options, the user set flags).
std::string flagName(const std::string& option)
{
  if (option == "agreement_tolerance")
  {
    return "--tolerance";
  }
  if (option == "k")
  {
    return "the number of readings";
  }
  std::string flag = "--" + option;
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

void printResult(const core::Result& result)
{
  std::printf("rank,x,y,theta,inliers,rms,unambiguous\n");
  const bool unambiguous = core::isUnambiguous(result);
  int rank = 1;
  for (const core::Candidate& c : result.candidates)
  {
    std::printf("%d,%.6f,%.6f,%.6f,%d,%.6g,%d\n", rank, c.pose.x, c.pose.y, c.pose.theta, c.inliers, c.rms_residual,
                rank == 1 && unambiguous ? 1 : 0);
    ++rank;
  }
  std::fflush(stdout);
}

void printTimes(const core::Result& result)
{
  const core::StageTimes& t = result.times;
  std::fprintf(stderr,
               "k'=%d readings=%d candidates=%zu  times [ms]: table %.1f preimages %.1f count %.1f "
               "components %.1f verification %.1f polish %.1f total %.1f\n",
               result.min_inliers_used, result.readings_used, result.candidates.size(), 1e3 * t.table,
               1e3 * t.preimages, 1e3 * t.count, 1e3 * t.components, 1e3 * t.verification, 1e3 * t.polish,
               1e3 * t.total);
}
}  // namespace

int main(int argc, char** argv)
{
  try
  {
    const Arguments args = parseArguments(argc, argv);
    const std::vector<std::string> problems = core::validate(args.options, flagName);
    if (!problems.empty())
    {
      std::string text = "invalid options:";
      for (const std::string& p : problems)
      {
        text += "\n  " + p;
      }
      throw UsageError(text);
    }
    const CsvReadings csv = readCsv(args.csv, args.max_range);
    validateCsv(csv, args.csv, args.options);
    auto map = std::make_shared<const core::MapRayCaster>(core::loadPolyFile(args.map));
    core::Localizer localizer(map, args.options);
    const core::Result result = localizer.localize(csv.readings);
    const std::string cache_warning = core::tableCacheWarning(localizer);
    if (!cache_warning.empty())
    {
      std::cerr << "fdml_localize: warning: distance-table cache: " << cache_warning << "\n";
    }
    printResult(result);
    if (args.verbose)
    {
      printTimes(result);
    }
    return 0;
  }
  catch (const UsageError& e)
  {
    std::cerr << "fdml_localize: " << e.what() << "\n" << kUsage;
    return 2;
  }
  catch (const core::MapError& e)
  {
    std::cerr << "fdml_localize: map: " << e.what() << "\n";
    return 2;
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "fdml_localize: " << e.what() << "\n";
    return 2;
  }
  catch (const std::bad_alloc&)
  {
    std::cerr << "fdml_localize: out of memory (try a smaller --resolution)\n";
    return 2;
  }
  catch (const std::exception& e)
  {
    std::cerr << "fdml_localize: " << e.what() << "\n";
    return 1;
  }
}
