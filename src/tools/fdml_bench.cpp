// fdml_bench: the paper's benchmark protocol (method.md section 5) on any maps. Prints the
// paper-style table on stdout, progress on stderr, one CSV row per trial with --csv.
#include "fdml_localization/benchmark/benchmark_runner.h"
#include "fdml_localization/core/util/text_parsing.h"
#include "fdml_localization/simulation/map_generators.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace
{
namespace core = fdml_localization::core;

/// Relative radius noise of the --random polygon: radii uniform in [0.65, 1.35] x mean radius,
/// the standard deviation (0.2) of the public prototype's Gaussian radii.
constexpr double kRandomRadiusNoise = 0.35;

const char* kUsage = "usage: fdml_bench --map PATH[:SCALE] [--map ...] [--random VERTICES[:SCALE]]\n"
                     "                  --obstacles 10,30 [--radius 0.1] [--k 10] [--min-inliers 6|auto]\n"
                     "                  --resolution 50,100,150,200 --trials 50 [--seed 1]\n"
                     "                  [--method robust|paper|baseline[,...]] [--engine voxel|adaptive|auto]\n"
                     "                  [--threads J] [--moving-obstacles] [--translate] [--noise SIGMA] [--fov DEG]\n"
                     "                  [--no-return constraint|weak|drop]\n"
                     "                  [--csv FILE] [--markdown FILE]\n"
                     "Scene names: the map file's stem, random<VERTICES> for --random; a SCALE other than 1\n"
                     "appends _x<SCALE> (checkpoint.poly:0.25 -> checkpoint_x0.25, --random 70:2 -> random70_x2).\n"
                     "--fov DEG gives every reading a cone of that full field of view [deg] in [0, 180]: the\n"
                     "nearest point of the map or a disc within +-DEG/2 (0, the default, = rays).\n";

struct UsageError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

std::vector<std::string> splitList(const std::string& text)
{
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
  {
    out.push_back(item);
  }
  return out;
}

std::vector<int> parseIntList(const std::string& text, const std::string& flag)
{
  std::vector<int> out;
  for (const std::string& item : splitList(text))
  {
    out.push_back(core::parseInteger(item, flag));
  }
  if (out.empty())
  {
    throw UsageError(flag + ": empty list");
  }
  return out;
}

std::string scaleSuffix(double scale)
{
  if (scale == 1.0)
  {
    return "";
  }
  char buf[64];
  std::snprintf(buf, sizeof(buf), "_x%g", scale);
  return buf;
}

core::BenchScene mapScene(const std::string& spec)
{
  const auto [path, scale] = core::splitScale(spec, "--map");
  const std::size_t slash = path.find_last_of('/');
  std::string stem = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = stem.rfind('.');
  if (dot != std::string::npos && dot > 0)
  {
    stem = stem.substr(0, dot);
  }
  core::PolygonMap map = fdml_localization::io::loadMapFile(path);  // .poly or .yaml
  if (scale != 1.0)
  {
    map = map.scaled(scale);
  }
  return { stem + scaleSuffix(scale), std::make_shared<const core::MapRayCaster>(std::move(map)) };
}

core::BenchScene randomScene(const std::string& spec, std::uint64_t seed)
{
  const auto [count, scale] = core::splitScale(spec, "--random");
  const int vertices = core::parseInteger(count, "--random");
  if (vertices < 3 || vertices > 100000)
  {
    throw UsageError("--random: VERTICES = " + count + " must be in [3, 100000]");
  }
  core::PolygonMap map = core::randomPolygon(vertices, 1.0, kRandomRadiusNoise, seed).scaled(scale);
  return { "random" + std::to_string(vertices) + scaleSuffix(scale),
           std::make_shared<const core::MapRayCaster>(std::move(map)) };
}

struct Cli
{
  core::BenchConfig config;
  std::vector<std::string> maps;
  std::vector<std::string> randoms;
  std::string csv;
  std::string markdown;
};

/// @p parse applied to the value of @p flag; its std::invalid_argument becomes a usage error
/// listing the @p allowed names.
template <typename Parse>
auto parseNamed(const std::string& value, const std::string& flag, const char* allowed, Parse parse)
{
  try
  {
    return parse(value);
  }
  catch (const std::invalid_argument&)
  {
    throw UsageError(flag + ": '" + value + "' is not one of " + allowed);
  }
}

std::vector<core::Method> parseMethods(const std::string& text)
{
  std::vector<core::Method> methods;
  for (const std::string& m : splitList(text))
  {
    methods.push_back(parseNamed(m, "--method", "robust, paper, baseline", core::parseMethod));
  }
  return methods;
}

std::uint64_t parseSeed(const std::string& text)
{
  const int seed = core::parseInteger(text, "--seed");
  if (seed < 0)
  {
    throw UsageError("--seed must be >= 0");
  }
  return static_cast<std::uint64_t>(seed);
}

/// --fov DEG: every reading's full field of view; the protocol takes half of it in radians
/// (validated there, in [0, pi/2]).
double parseFov(const std::string& text)
{
  const double degrees = core::parseNumber(text, "--fov");
  if (!(degrees >= 0.0 && degrees <= 180.0))
  {
    throw UsageError("--fov: " + text + " must be in [0, 180] degrees (0 = rays)");
  }
  return 0.5 * degrees * core::kPi / 180.0;
}

/// The flags that take a value, each storing it into @p cli.
std::map<std::string, std::function<void(const std::string&)>> valueFlags(Cli& cli)
{
  core::BenchConfig& c = cli.config;
  core::ProtocolOptions& p = c.protocol;
  return {
    { "--map", [&cli](const std::string& v) { cli.maps.push_back(v); } },
    { "--random", [&cli](const std::string& v) { cli.randoms.push_back(v); } },
    { "--obstacles", [&c](const std::string& v) { c.obstacles = parseIntList(v, "--obstacles"); } },
    { "--radius", [&p](const std::string& v) { p.obstacle_radius = core::parseNumber(v, "--radius"); } },
    { "--k", [&p](const std::string& v) { p.readings = core::parseInteger(v, "--k"); } },
    { "--min-inliers",
      [&c](const std::string& v) { c.min_inliers = v == "auto" ? 0 : core::parseInteger(v, "--min-inliers"); } },
    { "--resolution", [&c](const std::string& v) { c.resolutions = parseIntList(v, "--resolution"); } },
    { "--trials", [&c](const std::string& v) { c.trials = core::parseInteger(v, "--trials"); } },
    { "--seed", [&c](const std::string& v) { c.seed = parseSeed(v); } },
    { "--method",
      [&c](const std::string& v) {
        const std::vector<core::Method> methods = parseMethods(v);
        c.methods.insert(c.methods.end(), methods.begin(), methods.end());
      } },
    { "--engine",
      [&c](const std::string& v) {
        c.engine = parseNamed(v, "--engine", "voxel, adaptive, auto", core::parseEngine);
      } },
    { "--threads", [&c](const std::string& v) { c.threads = core::parseInteger(v, "--threads"); } },
    { "--noise", [&p](const std::string& v) { p.noise = core::parseNumber(v, "--noise"); } },
    { "--fov", [&p](const std::string& v) { p.half_angle = parseFov(v); } },
    { "--no-return",
      [&c](const std::string& v) {
        c.no_return = parseNamed(v, "--no-return", "constraint, weak, drop", core::parseNoReturn);
      } },
    { "--csv", [&cli](const std::string& v) { cli.csv = v; } },
    { "--markdown", [&cli](const std::string& v) { cli.markdown = v; } },
  };
}

/// Parses the command line; sets @p help (and nothing else) on --help.
Cli parseArgs(int argc, char** argv, bool* help)
{
  Cli cli;
  cli.config.methods.clear();
  const auto flags = valueFlags(cli);
  for (int i = 1; i < argc; ++i)
  {
    const std::string flag = argv[i];
    const auto it = flags.find(flag);
    if (flag == "--help" || flag == "-h")
    {
      *help = true;
      return cli;
    }
    if (flag == "--moving-obstacles")
    {
      cli.config.protocol.moving_obstacles = true;
    }
    else if (flag == "--translate")
    {
      cli.config.protocol.translate = true;
    }
    else if (it == flags.end())
    {
      throw UsageError("unknown option '" + flag + "'");
    }
    else if (i + 1 >= argc)
    {
      throw UsageError(flag + " needs a value");
    }
    else
    {
      it->second(argv[++i]);
    }
  }
  if (cli.config.methods.empty())
  {
    cli.config.methods.push_back(core::Method::Robust);
  }
  return cli;
}

std::string commandLine(int argc, char** argv)
{
  std::string out = "fdml_bench";
  for (int i = 1; i < argc; ++i)
  {
    out += std::string(" ") + argv[i];
  }
  return out;
}

std::string utcNow()
{
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof(buf), "%Y-%m-%d %H:%M:%S UTC", std::gmtime(&now));
  return buf;
}

/// Parses and validates the command line into @p cli (scenes loaded); false on --help.
bool setUp(int argc, char** argv, Cli* cli)
{
  bool help = false;
  *cli = parseArgs(argc, argv, &help);
  if (help)
  {
    return false;
  }
  for (const std::string& spec : cli->maps)
  {
    cli->config.scenes.push_back(mapScene(spec));
  }
  for (const std::string& spec : cli->randoms)
  {
    cli->config.scenes.push_back(randomScene(spec, cli->config.seed));
  }
  const std::vector<std::string> issues = core::validate(cli->config);
  if (!issues.empty())
  {
    std::string msg = "invalid options:";
    for (const std::string& s : issues)
    {
      msg += "\n  " + s;
    }
    throw UsageError(msg);
  }
  return true;
}

void writeMarkdown(const Cli& cli, const std::string& command, const std::string& started,
                   const std::vector<core::BenchSummary>& summary)
{
  std::ofstream md(cli.markdown);
  if (!md)
  {
    throw std::runtime_error("--markdown: cannot write '" + cli.markdown + "'");
  }
  md << "Command: `" << command << "`  \nStarted: " << started << ", finished: " << utcNow()
     << "  \nSparsity k' = " << core::sparsityKPrime(cli.config) << "\n\n"
     << core::formatMarkdownTable(summary) << "\nPaper-style (pooled over n):\n\n"
     << core::formatPaperTable(summary);
}

void run(const Cli& cli, const std::string& command)
{
  std::ofstream csv;
  if (!cli.csv.empty())
  {
    csv.open(cli.csv);
    if (!csv)
    {
      throw std::runtime_error("--csv: cannot write '" + cli.csv + "'");
    }
    csv << core::csvHeader() << '\n' << std::flush;
  }
  const auto on_row = [&csv](const core::BenchRow& row) {
    if (csv.is_open())
    {
      csv << core::csvRow(row) << '\n' << std::flush;
    }
  };
  const std::string started = utcNow();
  const core::BenchRun result = core::runBenchmark(cli.config, on_row, &std::cerr);
  const std::vector<core::BenchSummary> summary = core::summarize(result.rows, result.tables);
  std::cout << core::formatTable(summary) << "\nPaper-style table (success pooled over n):\n"
            << core::formatPaperTable(summary);
  if (!cli.markdown.empty())
  {
    writeMarkdown(cli, command, started, summary);
  }
}
}  // namespace

int main(int argc, char** argv)
{
  Cli cli;
  try
  {
    if (!setUp(argc, argv, &cli))
    {
      std::cout << kUsage;
      return 0;
    }
  }
  catch (const std::exception& e)
  {
    std::cerr << "fdml_bench: " << e.what() << "\n" << kUsage;
    return 2;
  }
  try
  {
    run(cli, commandLine(argc, argv));
  }
  catch (const std::exception& e)
  {
    if (cli.config.engine == core::Engine::Adaptive)
    {
      std::cerr << "fdml_bench: --engine adaptive failed (is the adaptive engine available?): " << e.what() << "\n";
    }
    else
    {
      std::cerr << "fdml_bench: " << e.what() << "\n";
    }
    return 1;
  }
  return 0;
}
