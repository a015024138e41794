// fdml_localize: global localization from a CSV of range readings on a .poly map.
//
//   fdml_localize --map MAP [--resolution N] [--min-inliers K|auto] [--method robust|paper|baseline]
//                 [--range-tolerance T] [--tolerance EPS] [--threads J] [--engine voxel|adaptive]
//                 [--cache-dir DIR] [--theta-resolution N] [--max-candidates M] [--max-range R]
//                 [--verbose] READINGS.csv
//
// READINGS.csv: header "gx,gy,gtheta,d" (optionally ",max_range"), one reading per line
// [m, rad]; d may be "inf" (no return within max_range). Prints "rank,x,y,theta,inliers,rms"
// and one candidate per line, best first; exit 0 (also with no candidate), 2 on bad input.
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/util/text_parsing.h"

#include <cerrno>
#include <cmath>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
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

std::vector<core::Reading> readCsv(const std::string& path, double default_max_range)
{
  std::ifstream in(path);
  if (!in)
  {
    throw UsageError(path + ": cannot open");
  }
  std::string line;
  int line_no = 0;
  bool have_header = false;
  bool has_max_range = false;
  std::vector<core::Reading> readings;
  while (std::getline(in, line))
  {
    ++line_no;
    const std::string t = core::trim(line);
    if (t.empty() || t[0] == '#')
    {
      continue;
    }
    const std::string where = path + ":" + std::to_string(line_no);
    const std::vector<std::string> fields = splitCsv(t);
    if (!have_header)
    {
      if (t == "gx,gy,gtheta,d")
      {
        has_max_range = false;
      }
      else if (t == "gx,gy,gtheta,d,max_range")
      {
        has_max_range = true;
      }
      else
      {
        throw UsageError(where + ": expected the header 'gx,gy,gtheta,d' (optionally ',max_range'), got '" + t + "'");
      }
      have_header = true;
      continue;
    }
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
    readings.push_back(r);
  }
  if (!have_header)
  {
    throw UsageError(path + ": empty file (expected the header 'gx,gy,gtheta,d')");
  }
  return readings;
}

struct Arguments
{
  std::string map;
  std::string csv;
  core::LocalizerOptions options;
  double max_range = core::kInf;
  bool verbose = false;
};

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
    if (flag == "--map")
    {
      args.map = value();
    }
    else if (flag == "--resolution")
    {
      args.options.resolution = core::parseInteger(value(), flag);
    }
    else if (flag == "--theta-resolution")
    {
      args.options.theta_resolution = core::parseInteger(value(), flag);
    }
    else if (flag == "--min-inliers")
    {
      const std::string v = value();
      args.options.min_inliers = v == "auto" ? 0 : core::parseInteger(v, flag);
      if (v != "auto" && args.options.min_inliers < 3)
      {
        throw UsageError("--min-inliers " + v + ": must be 'auto' or an integer >= 3");
      }
    }
    else if (flag == "--method")
    {
      args.options.method = core::parseMethod(value());
    }
    else if (flag == "--engine")
    {
      args.options.engine = core::parseEngine(value());
    }
    else if (flag == "--range-tolerance")
    {
      args.options.range_tolerance = core::parseNumber(value(), flag);
    }
    else if (flag == "--tolerance")
    {
      args.options.agreement_tolerance = core::parseNumber(value(), flag);
    }
    else if (flag == "--threads")
    {
      args.options.threads = core::parseInteger(value(), flag);
    }
    else if (flag == "--cache-dir")
    {
      args.options.cache_dir = value();
    }
    else if (flag == "--max-candidates")
    {
      args.options.max_candidates = core::parseInteger(value(), flag);
    }
    else if (flag == "--max-range")
    {
      args.max_range = core::parseNumber(value(), flag, true);
    }
    else if (flag == "--verbose")
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
  const core::Certificate& c = result.certificate;
  std::fprintf(stderr,
               "certificate: no pose explains more than %d readings within the range tolerance; best candidate %d; "
               "regions at the bound %d (covered %d, excluded %d); complete %s\n",
               c.max_consensus_bound, c.best_consensus, c.regions_at_bound, c.regions_covered, c.regions_excluded,
               c.complete ? "yes" : "no");
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
    const std::vector<core::Reading> readings = readCsv(args.csv, args.max_range);
    auto map = std::make_shared<const core::MapRayCaster>(core::loadPolyFile(args.map));
    core::Localizer localizer(map, args.options);
    const core::Result result = localizer.localize(readings);
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
