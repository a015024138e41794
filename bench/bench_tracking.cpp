// One tracking update of one hypothesis (issue 17; Google Benchmark; main() is in another file).
//
// Batches: the apartment patrol of test/core/tracking (four range sensors at 10 Hz, five people,
// drifting odometry), k = FDML_BENCH_TRACK_K (default 10), a batch every 2 readings, 200 batches.
// Each timed call updates a tracker holding one hypothesis, seeded 3 cm / 3 cm / 0.02 rad off the
// truth of its batch (about the odometry error between two updates).
//   Tracking/Update    HypothesisTracker::update with one hypothesis
// Counters: median_ms (median per update), fixed (fraction of updates whose local solve found a
// fix within 5 cm and 1 degree of the truth).
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/tracking/hypothesis_tracker.h"
#include "tracking_drive.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

namespace
{
namespace core = fdml_localization::core;

std::vector<fdml_test::DriveBatch> patrolBatches(const std::shared_ptr<const core::MapRayCaster>& map, int k)
{
  const core::ScenarioConfig c = fdml_test::apartmentPatrol(5);
  fdml_test::Drive drive(fdml_test::simulate(c, map), k, 2);
  std::vector<fdml_test::DriveBatch> batches;
  fdml_test::DriveBatch batch;
  while (batches.size() < 200 && drive.next(&batch, 60.0))
  {
    batches.push_back(batch);
  }
  return batches;
}

void BM_TrackingUpdate(benchmark::State& state)
{
  const char* k_env = std::getenv("FDML_BENCH_TRACK_K");
  const int k = k_env ? std::max(3, std::atoi(k_env)) : 10;
  const auto map = std::make_shared<const core::MapRayCaster>(core::loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/"
                                                                                                                "apartm"
                                                                                                                "ent."
                                                                                                                "pol"
                                                                                                                "y"));
  const std::vector<fdml_test::DriveBatch> batches = patrolBatches(map, k);
  if (batches.empty())
  {
    state.SkipWithError("the patrol gave no batch");
    return;
  }
  std::vector<double> times, errors_cm, errors_deg;
  long fixed = 0;
  std::size_t i = 0;
  for (auto _ : state)
  {
    state.PauseTiming();
    const fdml_test::DriveBatch& batch = batches[i++ % batches.size()];
    core::HypothesisTracker tracker(map, core::TrackerOptions());
    core::Candidate seed;
    seed.pose = core::Pose2(batch.truth.x + 0.03, batch.truth.y - 0.03, batch.truth.theta + 0.02);
    tracker.seed({ seed }, batch.reference, 0.0);
    state.ResumeTiming();
    const auto start = std::chrono::steady_clock::now();
    tracker.update(batch.readings, batch.reference);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    const core::Hypothesis& h = tracker.hypotheses().front();
    const core::Pose2& fix = h.last_fix.pose;
    const bool right = (fix.position() - batch.truth.position()).norm() < 0.05 &&
                       std::abs(core::angleDiff(fix.theta, batch.truth.theta)) < M_PI / 180.0;
    fixed += h.misses == 0 && right ? 1 : 0;
    errors_cm.push_back(h.misses == 0 ? 100.0 * (fix.position() - batch.truth.position()).norm() : 1e9);
    errors_deg.push_back(h.misses == 0 ? std::abs(core::angleDiff(fix.theta, batch.truth.theta)) * 180.0 / M_PI : 1e9);
  }
  std::sort(times.begin(), times.end());
  state.counters["median_ms"] = times.empty() ? 0.0 : 1e3 * times[times.size() / 2];
  state.counters["fixed"] = static_cast<double>(fixed) / static_cast<double>(std::max<std::size_t>(times.size(), 1));
  state.counters["k"] = k;
  std::sort(errors_cm.begin(), errors_cm.end());
  std::sort(errors_deg.begin(), errors_deg.end());
  state.counters["median_cm"] = errors_cm.empty() ? 0.0 : errors_cm[errors_cm.size() / 2];
  state.counters["median_deg"] = errors_deg.empty() ? 0.0 : errors_deg[errors_deg.size() / 2];
}
BENCHMARK(BM_TrackingUpdate)->Name("Tracking/Update")->Unit(benchmark::kMillisecond)->Iterations(400);
}  // namespace
