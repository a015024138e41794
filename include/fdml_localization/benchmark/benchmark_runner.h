/**
 * @file benchmark_runner.h
 * @brief Runs the benchmark protocol over scenes, obstacle counts, resolutions and methods,
 *        with one Localizer per (scene, n, method) reused across all its trials.
 */
#pragma once

#include "fdml_localization/benchmark/benchmark_report.h"

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// A named scene: the static map the trials are drawn in and the localizer searches.
struct BenchScene
{
  std::string name;
  std::shared_ptr<const MapRayCaster> map;
};

/// What to run.
struct BenchConfig
{
  std::vector<BenchScene> scenes;
  std::vector<int> obstacles{ 10, 30 };     ///< m values
  std::vector<int> resolutions{ 50, 100 };  ///< n values, each in [16, 1024]
  int trials = 50;                          ///< per (scene, m), shared by every n and method
  std::uint64_t seed = 1;
  std::vector<Method> methods{ Method::Robust };
  /// Engine::Auto (resolveEngine()): the adaptive engine for the robust method, the voxel engine for
  /// the paper's and the baseline's (their voxel clouds)
  Engine engine = Engine::Auto;
  /// LocalizerOptions::no_return
  NoReturnPolicy no_return = NoReturnPolicy::Constraint;
  int min_inliers = 6;       ///< k'; 0 = automatic (robust only)
  int threads = 0;           ///< localizer threads; 0 = all cores
  ProtocolOptions protocol;  ///< protocol.obstacles is set per m
};

/// Every problem with the configuration, each naming the option and its allowed range.
std::vector<std::string> validate(const BenchConfig& config);

/// k' used to judge whether (k, k') sparsity held: min_inliers, or the paper's 6 when automatic.
int sparsityKPrime(const BenchConfig& config);

/**
 * @brief The localizer options for one method and resolution. With range noise sigma the
 *        preimage band is max(0.02, 3 sigma) and the agreement tolerance max(0.05, 4 sigma).
 *        k' is min_inliers for robust (0 = automatic), min_inliers or the paper's 6 for paper,
 *        and k for the baseline. Paper and baseline use the public prototype's settings: every
 *        candidate is returned, the paper method's agreement tolerance is its 2 m and the
 *        baseline has no agreement filter (1e9 m).
 */
LocalizerOptions benchLocalizerOptions(const BenchConfig& config, Method method, int n);

/// The outcome of a run.
struct BenchRun
{
  std::vector<BenchRow> rows;
  std::vector<TableBuild> tables;
};

/**
 * @brief Runs every (scene, n, method, m, trial). Trial t of (scene, m) is drawn from
 *        trialSeed(seed, scene, m, t), so every n and method sees the same trials.
 * @param on_row called after each localization (for streaming the CSV); may be empty
 * @param progress when not null, receives one progress line per (scene, n, method, m)
 * @throws std::invalid_argument for an invalid configuration or localizer options (for
 *         instance an engine that is not available), std::runtime_error on trial failure.
 */
BenchRun runBenchmark(const BenchConfig& config, const std::function<void(const BenchRow&)>& on_row,
                      std::ostream* progress);

}  // namespace core
}  // namespace fdml_localization
