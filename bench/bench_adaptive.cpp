// Both engines side by side against map size (Google Benchmark; main() is in another file).
//
// Maps: FDML_BENCH_ADAPTIVE_MAPS, a ':'-separated list of entries, each a .poly path (optionally
// "path@factor" to scale it, e.g. checkpoint.poly@0.25) or "building:WxH" (core::generateBuilding,
// seed 1). Default: maps/square_room.poly, maps/office.poly, maps/warehouse.poly and generated
// buildings 30x20, 60x40 and 100x100 m.
// Per map:
//   Engines/Adaptive/<map>   one localization with the adaptive engine, leaves of
//                            FDML_BENCH_LEAF m (default 0.1) and 1 degree (theta_resolution 360)
//   Engines/Voxel/<map>      the same with the voxel engine at n = the same cell count, capped at
//                            FDML_BENCH_VOXEL_MAX (default 400); its table is built once first
//                            (table_s, table_mb)
// Readings: the paper's protocol (a random free pose, 10 readings in place 2 pi / 10 apart,
// 10 random disc obstacles of radius 0.1 m not covering the sensor; 16 batches, seed 7); auto k'.
// Engines4of10/...: the same engines on a harder protocol: 4 of the 10 readings cut short (the
// robustness tests' unknown-obstacle hits), so the consensus is only 6 of 10.
// Region/<engine>/<with|without>: a search region around the part of a large map the robot
// drives, against none (see runRegion()).
// Counters: median_ms (median total per call), success (fraction of calls whose best candidate
// is within 1 cm and 0.1 degree of the truth), resolution, peak_rss_mb (process peak: run one
// benchmark per process for a clean figure).
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/simulation/map_generators.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/simulation/scene.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "bench_utils.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <filesystem>
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

struct Batch
{
  core::Pose2 truth;
  std::vector<core::Reading> readings;
};

double envDouble(const char* name, double fallback)
{
  const char* value = std::getenv(name);
  return value ? std::atof(value) : fallback;
}

/// A map from an entry of FDML_BENCH_ADAPTIVE_MAPS.
std::shared_ptr<const core::MapRayCaster> makeMap(const std::string& entry)
{
  if (entry.rfind("building:", 0) == 0)
  {
    core::BuildingOptions options;
    const std::string size = entry.substr(9);
    const std::size_t x = size.find('x');
    options.width = std::atof(size.substr(0, x).c_str());
    options.height = std::atof(size.substr(x + 1).c_str());
    return std::make_shared<const core::MapRayCaster>(core::generateBuilding(options));
  }
  const std::size_t at = entry.find('@');
  core::PolygonMap map = core::loadPolyFile(entry.substr(0, at));
  if (at != std::string::npos)
  {
    map = map.scaled(std::atof(entry.substr(at + 1).c_str()));
  }
  return std::make_shared<const core::MapRayCaster>(std::move(map));
}

std::string displayName(const std::string& entry)
{
  if (entry.rfind("building:", 0) == 0)
  {
    return "building_" + entry.substr(9);
  }
  return std::filesystem::path(entry.substr(0, entry.find('@'))).stem().string();
}

/// The paper's protocol (see the file comment); with @p outliers, instead 4 of the 10 exact
/// readings (random, longer than 0.3 m) are cut short to a random 10 to 80 % and by >= 0.15 m.
/// Truths and obstacles are drawn in @p area (empty = the map's bounding box).
std::vector<Batch> protocolBatches(const core::MapRayCaster& map, int count, bool outliers, core::Box2 area = {})
{
  std::mt19937_64 rng(7);
  const core::Box2& b = area.empty() ? map.map().bounds() : area;
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()), ut(-core::kPi, core::kPi);
  auto freePoint = [&]() {
    for (;;)
    {
      const core::Vec2 p(ux(rng), uy(rng));
      if (map.isFree(p))
      {
        return p;
      }
    }
  };
  std::vector<Batch> batches;
  auto shared = std::make_shared<const core::MapRayCaster>(map);
  for (int i = 0; i < count; ++i)
  {
    Batch batch;
    const core::Vec2 sensor = freePoint();
    batch.truth = core::Pose2(sensor.x(), sensor.y(), ut(rng));
    std::vector<core::Obstacle> obstacles;
    while (obstacles.size() < 10)
    {
      const core::Vec2 c = freePoint();
      if ((c - sensor).norm() > 0.1)
      {
        obstacles.push_back(core::Obstacle::disc(c, 0.1));
      }
    }
    core::Scene scene(shared);
    scene.setObstacles(outliers ? std::vector<core::Obstacle>() : obstacles);
    std::vector<int> long_ones;
    for (int r = 0; r < 10; ++r)
    {
      core::Reading reading;
      reading.offset = core::Pose2(0.0, 0.0, core::wrapAngle(core::kTwoPi * r / 10));
      reading.range = scene.cast(core::compose(batch.truth, reading.offset)).distance;
      batch.readings.push_back(reading);
      if (reading.range > 0.3)
      {
        long_ones.push_back(r);
      }
    }
    if (outliers)
    {
      std::shuffle(long_ones.begin(), long_ones.end(), rng);
      std::uniform_real_distribution<double> shrink(0.1, 0.8);
      for (std::size_t j = 0; j < 4 && j < long_ones.size(); ++j)
      {
        core::Reading& reading = batch.readings[long_ones[j]];
        reading.range = std::min(reading.range * shrink(rng), reading.range - 0.15);
      }
    }
    batches.push_back(std::move(batch));
  }
  return batches;
}

/// Localizes the batches in turn, one per iteration: median_ms (median total per call) and
/// success (fraction whose best candidate is within @p position [m] and @p angle [rad] of the truth).
void timeCalls(benchmark::State& state, core::Localizer& localizer, const std::vector<Batch>& batches, double position,
               double angle)
{
  std::vector<double> totals;
  long calls = 0;
  int success = 0;
  for (auto _ : state)
  {
    const Batch& batch = batches[calls % batches.size()];
    const core::Result result = localizer.localize(batch.readings);
    totals.push_back(result.times.total);
    success += !result.candidates.empty() &&
               (result.candidates.front().pose.position() - batch.truth.position()).norm() < position &&
               std::abs(core::angleDiff(result.candidates.front().pose.theta, batch.truth.theta)) < angle;
    ++calls;
  }
  std::sort(totals.begin(), totals.end());
  state.counters["median_ms"] = totals.empty() ? 0.0 : 1e3 * totals[totals.size() / 2];
  state.counters["success"] = static_cast<double>(success) / static_cast<double>(std::max(calls, 1L));
}

void runEngine(benchmark::State& state, const std::string& entry, core::Engine engine, bool outliers)
{
  const auto map = makeMap(entry);
  const core::Vec2 size = map->map().bounds().size();
  const int cells =
      std::max(64, static_cast<int>(std::ceil(std::max(size.x(), size.y()) / envDouble("FDML_BENCH_LEAF", 0.1))));
  core::LocalizerOptions options;
  options.engine = engine;
  if (engine == core::Engine::Voxel)
  {
    options.resolution = std::min(cells, static_cast<int>(envDouble("FDML_BENCH_VOXEL_MAX", 400)));
  }
  else
  {
    options.resolution = cells;
    options.theta_resolution = 360;
  }
  core::Localizer localizer(map, options);
  const auto start = std::chrono::steady_clock::now();
  localizer.prepare();
  state.counters["table_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (engine == core::Engine::Voxel)
  {
    state.counters["table_mb"] =
        static_cast<double>(dynamic_cast<core::VoxelEngine&>(localizer.engine()).table().memoryBytes()) /
        (1024.0 * 1024.0);
  }
  const std::vector<Batch> batches = protocolBatches(*map, 16, outliers);
  timeCalls(state, localizer, batches, 0.01, 0.1 * core::kPi / 180.0);
  state.counters["resolution"] = options.resolution;
  state.counters["peak_rss_mb"] = peakRssMb();
}

/// Region/<engine>/<with|without>: the defaults (resolution 100) on the 60 x 40 m building
/// where the robot only drives a 20 x 15 m corner, with and without that corner as the search
/// region (LocalizerOptions::search_region); truths drawn in the corner.
void runRegion(benchmark::State& state, core::Engine engine, bool with_region)
{
  const auto map = makeMap("building:60x40");
  const core::Box2& b = map->map().bounds();
  core::Box2 corner;
  corner.extend(b.min);
  corner.extend(b.min + core::Vec2(20.0, 15.0));
  core::LocalizerOptions options;
  options.engine = engine;
  if (with_region)
  {
    const core::Ring ring = {
      corner.min, { corner.max.x(), corner.min.y() }, corner.max, { corner.min.x(), corner.max.y() }
    };
    options.search_region = std::make_shared<const core::MapRayCaster>(core::PolygonMap::fromRings({ ring }));
  }
  core::Localizer localizer(map, options);
  const auto start = std::chrono::steady_clock::now();
  localizer.prepare();
  state.counters["table_s"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<Batch> batches = protocolBatches(*map, 16, false, corner);
  timeCalls(state, localizer, batches, 0.05, 2.0 * core::kPi / 180.0);
  state.counters["peak_rss_mb"] = peakRssMb();
}

int registerAll()
{
  for (const core::Engine engine : { core::Engine::Adaptive, core::Engine::Voxel })
  {
    for (const bool with_region : { false, true })
    {
      const std::string name = std::string("Region/") + core::toString(engine) + (with_region ? "/with" : "/without");
      benchmark::RegisterBenchmark(name.c_str(),
                                   [engine, with_region](benchmark::State& s) { runRegion(s, engine, with_region); })
          ->Iterations(16)
          ->Unit(benchmark::kMillisecond)
          ->UseRealTime();
    }
  }
  std::vector<std::string> entries;
  if (const char* env = std::getenv("FDML_BENCH_ADAPTIVE_MAPS"))
  {
    entries = split(env, ':');
  }
  else
  {
    const std::string dir = std::string(FDML_SOURCE_DIR) + "/maps/";
    entries = { dir + "square_room.poly", dir + "office.poly", dir + "warehouse.poly",
                "building:30x20",         "building:60x40",    "building:100x100" };
  }
  for (const std::string& entry : entries)
  {
    for (const bool outliers : { false, true })
    {
      for (const core::Engine engine : { core::Engine::Adaptive, core::Engine::Voxel })
      {
        const std::string name = std::string(outliers ? "Engines4of10/" : "Engines/") +
                                 (engine == core::Engine::Voxel ? "Voxel/" : "Adaptive/") + displayName(entry);
        benchmark::RegisterBenchmark(
            name.c_str(), [entry, engine, outliers](benchmark::State& s) { runEngine(s, entry, engine, outliers); })
            ->Iterations(16)
            ->Unit(benchmark::kMillisecond)
            ->UseRealTime();
      }
    }
  }
  return 0;
}

const int kRegistered = registerAll();

}  // namespace
