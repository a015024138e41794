// Per-stage timings of the voxel localizer (Google Benchmark; main() is in another file).
//
// Maps: FDML_BENCH_MAPS, a ':'-separated list of .poly files (default: maps/office.poly of the
// source tree). Resolutions: FDML_BENCH_RESOLUTIONS, ','-separated (default 100,200).
// Per map and resolution:
//   Localizer/TableBuild/<map>/<n>   one distance-table build (exact ray casts, all threads)
//   Localizer/Localize_k6/<map>/<n>   one k = 10 localization with the table in memory (the
//                                    paper's protocol: readings in place, 10 disc obstacles of
//                                    0.1 m; k' = 6), with each stage's mean time as a counter [ms]
//   Localizer/Localize_auto/<map>/<n> the same with automatic k' (maximum consensus)
// Each benchmark also reports the process's peak resident memory so far (peak_rss_mb).
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/scene.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "bench_utils.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace
{
namespace core = fdml_localization::core;
using fdml_localization::bench::peakRssMb;
using fdml_localization::bench::split;

std::shared_ptr<const core::MapRayCaster> loadMap(const std::string& path)
{
  static std::map<std::string, std::shared_ptr<const core::MapRayCaster>> maps;
  auto it = maps.find(path);
  if (it == maps.end())
  {
    it = maps.emplace(path, std::make_shared<const core::MapRayCaster>(core::loadPolyFile(path))).first;
  }
  return it->second;
}

/// One batch of the paper's protocol: a random free pose, 10 readings in place 2 pi / 10 apart,
/// 10 random disc obstacles of radius 0.1 m that do not cover the sensor.
std::vector<core::Reading> protocolBatch(const std::shared_ptr<const core::MapRayCaster>& map, std::mt19937_64& rng)
{
  const core::Box2& b = map->map().bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x());
  std::uniform_real_distribution<double> uy(b.min.y(), b.max.y());
  std::uniform_real_distribution<double> ut(-core::kPi, core::kPi);
  auto freePoint = [&]() {
    for (;;)
    {
      const core::Vec2 p(ux(rng), uy(rng));
      if (map->isFree(p))
      {
        return p;
      }
    }
  };
  const core::Vec2 sensor = freePoint();
  const core::Pose2 truth(sensor.x(), sensor.y(), ut(rng));
  std::vector<core::Obstacle> obstacles;
  while (obstacles.size() < 10)
  {
    const core::Vec2 c = freePoint();
    if ((c - sensor).norm() > 0.1)
    {
      obstacles.push_back(core::Obstacle::disc(c, 0.1));
    }
  }
  core::Scene scene(map);
  scene.setObstacles(obstacles);
  std::vector<core::Reading> readings;
  for (int i = 0; i < 10; ++i)
  {
    core::Reading r;
    r.offset = core::Pose2(0.0, 0.0, core::wrapAngle(core::kTwoPi * i / 10));
    r.range = scene.cast(core::compose(truth, r.offset)).distance;
    readings.push_back(r);
  }
  return readings;
}

void tableBuild(benchmark::State& state, const std::string& path, int n)
{
  const auto map = loadMap(path);
  const core::GridSpec spec = core::GridSpec::fromMap(map->map(), n, 0);
  for (auto _ : state)
  {
    const core::DistanceTable table = core::DistanceTable::build(*map, spec, 0);
    benchmark::DoNotOptimize(table.values().data());
    state.counters["table_mb"] = static_cast<double>(table.memoryBytes()) / (1024.0 * 1024.0);
  }
  state.counters["voxels"] = static_cast<double>(spec.voxelCount());
  state.counters["peak_rss_mb"] = peakRssMb();
}

void localize(benchmark::State& state, const std::string& path, int n, int min_inliers)
{
  const auto map = loadMap(path);
  core::LocalizerOptions options;
  options.resolution = n;
  options.min_inliers = min_inliers;
  core::VoxelEngine engine(map, options);
  engine.prepare();
  std::mt19937_64 rng(7);
  std::vector<std::vector<core::Reading>> batches;
  for (int i = 0; i < 16; ++i)
  {
    batches.push_back(protocolBatch(map, rng));
  }
  core::StageTimes sum;
  std::vector<double> totals;
  long calls = 0;
  double candidates = 0.0;
  for (auto _ : state)
  {
    const core::Result result = engine.localize(batches[calls % batches.size()]);
    sum.preimages += result.times.preimages;
    sum.count += result.times.count;
    sum.components += result.times.components;
    sum.verification += result.times.verification;
    sum.polish += result.times.polish;
    totals.push_back(result.times.total);
    candidates += static_cast<double>(result.candidates.size());
    ++calls;
  }
  const double scale = 1e3 / static_cast<double>(std::max(calls, 1L));
  state.counters["preimages_ms"] = sum.preimages * scale;
  state.counters["count_ms"] = sum.count * scale;
  state.counters["components_ms"] = sum.components * scale;
  state.counters["verification_ms"] = sum.verification * scale;
  state.counters["polish_ms"] = sum.polish * scale;
  std::sort(totals.begin(), totals.end());
  state.counters["median_ms"] = totals.empty() ? 0.0 : 1e3 * totals[totals.size() / 2];
  state.counters["candidates"] = candidates / static_cast<double>(std::max(calls, 1L));
  state.counters["peak_rss_mb"] = peakRssMb();
}

/// Registers the benchmarks for every configured map and resolution.
int registerAll()
{
  std::vector<std::string> maps;
  if (const char* env = std::getenv("FDML_BENCH_MAPS"))
  {
    maps = split(env, ':');
  }
  else
  {
    const std::string office = std::string(FDML_SOURCE_DIR) + "/maps/office.poly";
    if (std::filesystem::exists(office))
    {
      maps.push_back(office);
    }
  }
  std::vector<int> resolutions = { 100, 200 };
  if (const char* env = std::getenv("FDML_BENCH_RESOLUTIONS"))
  {
    resolutions.clear();
    for (const std::string& r : split(env, ','))
    {
      resolutions.push_back(std::atoi(r.c_str()));
    }
  }
  for (const std::string& path : maps)
  {
    const std::string name = std::filesystem::path(path).stem().string();
    for (int n : resolutions)
    {
      const std::string suffix = "/" + name + "/" + std::to_string(n);
      benchmark::RegisterBenchmark(("Localizer/TableBuild" + suffix).c_str(),
                                   [path, n](benchmark::State& s) { tableBuild(s, path, n); })
          ->Iterations(1)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
      for (int min_inliers : { 6, 0 })
      {
        const std::string kind = min_inliers > 0 ? "Localize_k6" : "Localize_auto";
        benchmark::RegisterBenchmark(("Localizer/" + kind + suffix).c_str(),
                                     [path, n, min_inliers](benchmark::State& s) { localize(s, path, n, min_inliers); })
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime()
            ->MinTime(2.0);
      }
    }
  }
  return 0;
}

const int kRegistered = registerAll();

}  // namespace
