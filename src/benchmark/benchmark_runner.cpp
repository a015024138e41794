#include "fdml_localization/benchmark/benchmark_runner.h"
#include "fdml_localization/core/util/stopwatch.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ostream>
#include <sstream>
#include <stdexcept>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr int kPaperKPrime = 6;
/// The public prototype's experiment script filters the paper method's candidates with
/// epsilon = 2 m, and its FDML baseline has no agreement filter at all; both return every
/// candidate and are scored on the nearest one.
constexpr double kPaperAgreementTolerance = 2.0;
constexpr double kNoAgreementFilter = kMaxAgreementTolerance;
constexpr int kAllCandidates = 1000000;

std::string joinIssues(const std::string& what, const std::vector<std::string>& issues)
{
  std::ostringstream msg;
  msg << what;
  for (const std::string& s : issues)
  {
    msg << "\n  " << s;
  }
  return msg.str();
}
}  // namespace

namespace
{
/// The problems with the scenes and the lists of m, n, trials and methods.
void validateLists(const BenchConfig& c, std::vector<std::string>* issues)
{
  if (c.scenes.empty())
  {
    issues->push_back("no scene: give at least one --map or --random");
  }
  for (const BenchScene& s : c.scenes)
  {
    if (!s.map || s.map->map().empty())
    {
      issues->push_back("scene '" + s.name + "' has no map");
    }
  }
  if (c.obstacles.empty())
  {
    issues->push_back("obstacles (m) list is empty");
  }
  for (int m : c.obstacles)
  {
    if (m < 0 || m > 10000)
    {
      issues->push_back("obstacles (m) = " + std::to_string(m) + " must be in [0, 10000]");
    }
  }
  if (c.resolutions.empty())
  {
    issues->push_back("resolution (n) list is empty");
  }
  if (c.trials < 1 || c.trials > 1000000)
  {
    issues->push_back("trials = " + std::to_string(c.trials) + " must be in [1, 1000000]");
  }
  if (c.methods.empty())
  {
    issues->push_back("method list is empty");
  }
}

/// The localizer options of every run: one validation (the core's), under the tool's flag names.
void validateLocalizerOptions(const BenchConfig& c, std::vector<std::string>* issues)
{
  const int k = c.protocol.readings;
  if (c.min_inliers > k)  // the lower bound is the core's (below)
  {
    issues->push_back("min-inliers (k') = " + std::to_string(c.min_inliers) +
                      " must be 'auto' or in [3, k = " + std::to_string(k) + "]");
  }
  const auto flag = [k](const std::string& option) {
    if (option == "k")
    {
      return "k = " + std::to_string(k);
    }
    std::string name = "--" + option;
    std::replace(name.begin(), name.end(), '_', '-');
    return name;
  };
  for (Method method : c.methods)
  {
    for (int n : c.resolutions)
    {
      for (const std::string& issue : validate(benchLocalizerOptions(c, method, n), flag))
      {
        if (std::find(issues->begin(), issues->end(), issue) == issues->end())
        {
          issues->push_back(issue);
        }
      }
    }
  }
}
}  // namespace

std::vector<std::string> validate(const BenchConfig& c)
{
  std::vector<std::string> issues = validate(c.protocol);
  validateLists(c, &issues);
  validateLocalizerOptions(c, &issues);
  return issues;
}

int sparsityKPrime(const BenchConfig& config)
{
  return config.min_inliers > 0 ? config.min_inliers : std::min(kPaperKPrime, config.protocol.readings);
}

LocalizerOptions benchLocalizerOptions(const BenchConfig& config, Method method, int n)
{
  LocalizerOptions o;
  o.engine = config.engine;
  o.no_return = config.no_return;
  o.method = method;
  o.resolution = n;
  o.threads = config.threads;
  const double sigma = config.protocol.noise;
  o.range_tolerance = std::max(o.range_tolerance, 3.0 * sigma);
  o.agreement_tolerance = std::max(o.agreement_tolerance, 4.0 * sigma);
  switch (method)
  {
    case Method::Robust:
      o.min_inliers = config.min_inliers;
      break;
    case Method::Paper:
      o.min_inliers = sparsityKPrime(config);
      o.agreement_tolerance = std::max(o.agreement_tolerance, kPaperAgreementTolerance);
      o.max_candidates = kAllCandidates;
      break;
    case Method::Baseline:
      o.min_inliers = config.protocol.readings;
      o.agreement_tolerance = kNoAgreementFilter;
      o.max_candidates = kAllCandidates;
      break;
  }
  return o;
}

namespace
{
/// The trials of each m, drawn once and shared by every n and method.
std::vector<std::vector<Trial>> drawTrials(const BenchConfig& config, const BenchScene& scene)
{
  std::vector<std::vector<Trial>> trials(config.obstacles.size());
  for (std::size_t mi = 0; mi < config.obstacles.size(); ++mi)
  {
    ProtocolOptions protocol = config.protocol;
    protocol.obstacles = config.obstacles[mi];
    for (int t = 0; t < config.trials; ++t)
    {
      trials[mi].push_back(
          generateTrial(scene.map, protocol, trialSeed(config.seed, scene.name, protocol.obstacles, t)));
    }
  }
  return trials;
}

/// What one cell (scene, m, n, method) of the run shares.
struct Cell
{
  const BenchScene& scene;
  int m = 0;
  int n = 0;
  Method method = Method::Robust;
};

/// Localizes every trial of one cell; returns the number of successes (paper criterion).
int runCell(const BenchConfig& config, const Cell& cell, Localizer& localizer, const std::vector<Trial>& trials,
            const std::function<void(const BenchRow&)>& on_row, BenchRun* run)
{
  const int k_prime = sparsityKPrime(config);
  int successes = 0;
  for (int t = 0; t < config.trials; ++t)
  {
    const Trial& trial = trials[static_cast<std::size_t>(t)];
    const auto start = std::chrono::steady_clock::now();
    const Result result = localizer.localize(trial.readings);
    // The table was built by prepare() before (the engine reports that time again in the first
    // result's times.table, so it is not subtracted here).
    const double ms = 1000.0 * secondsSince(start);
    BenchRow row;
    row.scene = cell.scene.name;
    row.m = cell.m;
    row.n = cell.n;
    row.method = toString(cell.method);
    row.trial = t;
    row.score = scoreTrial(trial, result, cell.scene.map->map().bounds(), cell.n, k_prime, ms);
    row.fov_deg = 2.0 * config.protocol.half_angle * 180.0 / kPi;
    successes += row.score.success_paper ? 1 : 0;
    if (on_row)
    {
      on_row(row);
    }
    run->rows.push_back(row);
  }
  return successes;
}
}  // namespace

BenchRun runBenchmark(const BenchConfig& config, const std::function<void(const BenchRow&)>& on_row,
                      std::ostream* progress)
{
  const std::vector<std::string> issues = validate(config);
  if (!issues.empty())
  {
    throw std::invalid_argument(joinIssues("invalid benchmark configuration:", issues));
  }
  const auto run_start = std::chrono::steady_clock::now();
  const std::size_t total_cells =
      config.scenes.size() * config.resolutions.size() * config.methods.size() * config.obstacles.size();
  std::size_t done_cells = 0;
  BenchRun run;
  for (const BenchScene& scene : config.scenes)
  {
    const std::vector<std::vector<Trial>> trials = drawTrials(config, scene);
    for (int n : config.resolutions)
    {
      for (Method method : config.methods)
      {
        Localizer localizer(scene.map, benchLocalizerOptions(config, method, n));
        const auto table_start = std::chrono::steady_clock::now();
        localizer.prepare();
        run.tables.push_back(TableBuild{ scene.name, n, toString(method), secondsSince(table_start) });
        for (std::size_t mi = 0; mi < config.obstacles.size(); ++mi)
        {
          const Cell cell{ scene, config.obstacles[mi], n, method };
          const int successes = runCell(config, cell, localizer, trials[mi], on_row, &run);
          ++done_cells;
          if (progress)
          {
            char line[256];
            std::snprintf(line, sizeof(line),
                          "[%zu/%zu] %s m=%d n=%d %s: success %d/%d (table %.2f s, elapsed %.0f s)\n", done_cells,
                          total_cells, scene.name.c_str(), cell.m, n, toString(method), successes, config.trials,
                          run.tables.back().seconds, secondsSince(run_start));
            *progress << line << std::flush;
          }
        }
      }
    }
  }
  return run;
}

}  // namespace core
}  // namespace fdml_localization
