// fdml_localize: global localization from a CSV of range readings on a map (.poly, or a
// map_server .yaml grid; a map from a grid gets the grid tolerances, core::withGridTolerances).
// Usage: kUsage below (fdml_localize --help). READINGS.csv: see readings_csv.h. Prints "rank,x,y,theta,inliers,rms"
// and one candidate per line, best first; exit 0 (also with no candidate), 2 on bad input.
#include "readings_csv.h"

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/map/grid/grid_tolerances.h"
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/util/text_parsing.h"
#include "fdml_localization/io/map_files.h"

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

namespace io = fdml_localization::io;
namespace tools = fdml_localization::tools;

/// Bad input: reported on stderr, exit code 2.
using UsageError = tools::InputError;

const char* kUsage = "usage: fdml_localize --map MAP.poly|MAP.yaml [--resolution N] [--min-inliers K|auto]\n"
                     "                     [--method robust|paper|baseline] [--range-tolerance T] [--tolerance EPS]\n"
                     "                     [--threads J] [--engine voxel|adaptive|auto] [--cache-dir DIR]\n"
                     "                     [--theta-resolution N] [--max-candidates M] [--max-range R] [--verbose]\n"
                     "                     [--no-return constraint|weak|drop] [--region MAP.poly|MAP.yaml]\n"
                     "                     [--region-seed X,Y] READINGS.csv\n"
                     "--region: search only where the robot's base may be (the free space of that map file;\n"
                     "  with --region-seed, of a grid's free region holding that point [m])\n"
                     "READINGS.csv: header gx,gy,gtheta,d[,max_range][,fov] (fov: full field of view [deg])\n";

struct Arguments
{
  std::string map;
  std::string region;  ///< --region: a search region's map file
  bool region_seed = false;
  core::Vec2 seed = core::Vec2::Zero();  ///< --region-seed [m]
  std::string csv;
  core::LocalizerOptions options;
  double max_range = core::kInf;
  bool verbose = false;
  core::ExplicitTolerances set;  ///< tolerances given on the command line (kept on a grid map)
};

/// Applies one flag that names a method, engine or no-return policy; false for other flags.
bool applyNameFlag(const std::string& flag, const std::function<std::string()>& value, core::LocalizerOptions& o)
{
  if (flag == "--method")
  {
    o.method = core::parseMethod(value());
  }
  else if (flag == "--engine")
  {
    o.engine = core::parseEngine(value());
  }
  else if (flag == "--no-return")
  {
    o.no_return = core::parseNoReturn(value());
  }
  else
  {
    return false;
  }
  return true;
}

/// Applies one flag that names a file (the map, a search region); false for other flags.
bool applyFileFlag(const std::string& flag, const std::function<std::string()>& value, Arguments& args)
{
  if (flag == "--map")
  {
    args.map = value();
  }
  else if (flag == "--region")
  {
    args.region = value();
  }
  else if (flag == "--region-seed")
  {
    args.region_seed = true;
    core::parsePoint(value(), flag, args.seed.x(), args.seed.y());
  }
  else
  {
    return false;
  }
  return true;
}

/// Applies one option flag that takes a value; false when @p flag is not one of them.
bool applyValueFlag(const std::string& flag, const std::function<std::string()>& value, Arguments& args)
{
  core::LocalizerOptions& o = args.options;
  if (applyNameFlag(flag, value, o) || applyFileFlag(flag, value, args))
  {
    return true;
  }
  if (flag == "--resolution" || flag == "--theta-resolution" || flag == "--threads" || flag == "--max-candidates")
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
  else if (flag == "--range-tolerance")
  {
    o.range_tolerance = core::parseNumber(value(), flag);
    args.set.range_tolerance = true;
  }
  else if (flag == "--tolerance")
  {
    o.agreement_tolerance = core::parseNumber(value(), flag);
    args.set.agreement_tolerance = true;
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
  if (args.region_seed && args.region.empty())
  {
    throw UsageError("--region-seed needs --region");
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
  if (c.max_consensus_bound < 0)
  {
    std::fprintf(stderr, "certificate: none (this method's test proves no bound; best candidate %d)\n",
                 c.best_consensus);
    return;
  }
  std::fprintf(stderr,
               "certificate: no pose explains more than %d readings within the range tolerance; best candidate %d; "
               "regions at the bound %d (covered %d, excluded %d); complete %s\n",
               c.max_consensus_bound, c.best_consensus, c.regions_at_bound, c.regions_covered, c.regions_excluded,
               c.complete ? "yes" : "no");
}
/// The localizer for the map file, its grid tolerances and the search region of @p args.
core::Localizer localizerFor(const Arguments& args)
{
  io::MapFile file = io::readMapFile(args.map);
  auto map = std::make_shared<const core::MapRayCaster>(std::move(file.map));
  core::LocalizerOptions options = core::withGridTolerances(args.options, file.cell_size, args.set);
  if (!args.region.empty())
  {
    options.search_region = io::loadSearchRegion(args.region, args.region_seed ? &args.seed : nullptr);
  }
  return core::Localizer(map, options);
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
    const tools::CsvReadings csv = tools::readReadingsCsv(args.csv, args.max_range);
    tools::validateCsvReadings(csv, args.csv, args.options);
    core::Localizer localizer = localizerFor(args);
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
