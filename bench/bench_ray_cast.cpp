// Rays per second of the grid ray cast against the brute-force loop over every edge, on the
// office and warehouse maps (and a large generated building), on 1 and 2 threads.
// Each iteration casts a fixed batch of rays from random free points in an OpenMP loop;
// items_per_second is rays per second (wall-clock).
// ConeCast: the exact cone cast (core/geometry/cone_cast.h) of the same batch for fields of view
// of 0 (the ray), 2, 15, 27 and 30 deg, one thread; items_per_second is cones per second.
// ConePolish: the continuous polish (polishPose, robust_search.h) of 10 exact readings taken in
// place, 36 deg apart, with fields of view of 0 (rays) and 27 deg, from a start 3 cm and 1.5 deg
// off the truth, 64 random free poses (seed 99), one thread; items_per_second is polishes per second.
#include "fdml_localization/simulation/map_generators.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/robust_search.h"

#include <benchmark/benchmark.h>
#include <omp.h>

#include <memory>
#include <random>
#include <string>
#include <vector>

namespace
{
namespace core = fdml_localization::core;

constexpr int kBatch = 8192;

struct RayBatch
{
  std::vector<core::Vec2> origins;
  std::vector<core::Vec2> dirs;
};

RayBatch makeBatch(const core::MapRayCaster& caster, std::uint64_t seed)
{
  RayBatch batch;
  std::mt19937_64 rng(seed);
  const core::Box2& b = caster.map().bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
  std::uniform_real_distribution<double> angle(-core::kPi, core::kPi);
  while (static_cast<int>(batch.origins.size()) < kBatch)
  {
    const core::Vec2 p(ux(rng), uy(rng));
    if (caster.isFree(p))
    {
      const double a = angle(rng);
      batch.origins.push_back(p);
      batch.dirs.emplace_back(std::cos(a), std::sin(a));
    }
  }
  return batch;
}

void castBatch(benchmark::State& state, std::shared_ptr<const core::MapRayCaster> caster, bool accelerated, int threads)
{
  const RayBatch batch = makeBatch(*caster, 1234);
  const core::SegmentGrid& grid = caster->grid();
  for (auto _ : state)
  {
    double sum = 0.0;
#pragma omp parallel for num_threads(threads) reduction(+ : sum) schedule(static)
    for (int i = 0; i < kBatch; ++i)
    {
      const core::RayHit hit = accelerated ? grid.cast(batch.origins[i], batch.dirs[i]) :
                                             grid.castBruteForce(batch.origins[i], batch.dirs[i]);
      sum += hit.distance;
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
  state.counters["edges"] = static_cast<double>(grid.segments().size());
}

void coneBatch(benchmark::State& state, std::shared_ptr<const core::MapRayCaster> caster, double fov_deg)
{
  const RayBatch batch = makeBatch(*caster, 1234);
  const double half_angle = 0.5 * fov_deg * core::kPi / 180.0;
  for (auto _ : state)
  {
    double sum = 0.0;
    for (int i = 0; i < kBatch; ++i)
    {
      const double theta = std::atan2(batch.dirs[i].y(), batch.dirs[i].x());
      sum += core::coneRange(*caster, core::Pose2(batch.origins[i].x(), batch.origins[i].y(), theta), half_angle);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}

/// Poses of the polish benchmark and their 10 exact readings in place (cones of @p half_angle).
struct PolishBatch
{
  std::vector<core::Pose2> truths;
  std::vector<std::vector<core::Reading>> readings;
};

PolishBatch makePolishBatch(const core::MapRayCaster& caster, double half_angle)
{
  PolishBatch batch;
  const RayBatch poses = makeBatch(caster, 99);
  for (int i = 0; static_cast<int>(batch.truths.size()) < 64 && i < kBatch; ++i)
  {
    const core::Pose2 truth(poses.origins[i].x(), poses.origins[i].y(),
                            std::atan2(poses.dirs[i].y(), poses.dirs[i].x()));
    std::vector<core::Reading> readings;
    for (int k = 0; k < 10; ++k)
    {
      core::Reading r;
      r.offset = core::Pose2(0.0, 0.0, core::wrapAngle(2.0 * core::kPi * k / 10.0));
      r.half_angle = half_angle;
      r.range = core::coneRange(caster, core::compose(truth, r.offset), half_angle);
      readings.push_back(r);
    }
    batch.truths.push_back(truth);
    batch.readings.push_back(readings);
  }
  return batch;
}

void polishBatch(benchmark::State& state, std::shared_ptr<const core::MapRayCaster> caster, double fov_deg)
{
  const PolishBatch batch = makePolishBatch(*caster, 0.5 * fov_deg * core::kPi / 180.0);
  const std::vector<bool> use(10, true);
  double error = 0.0;
  for (auto _ : state)
  {
    error = 0.0;
    for (std::size_t i = 0; i < batch.truths.size(); ++i)
    {
      const core::Pose2& t = batch.truths[i];
      const core::Pose2 start(t.x + 0.03, t.y - 0.02, t.theta + 0.026);
      const core::PolishOutcome out = core::polishPose(*caster, start, batch.readings[i], use, 0.05, 20, 0.01);
      error += (out.pose.position() - t.position()).norm();
    }
    benchmark::DoNotOptimize(error);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<long>(batch.truths.size()));
  state.counters["mean_err_mm"] = 1000.0 * error / static_cast<double>(batch.truths.size());
}

void registerAll()
{
  std::vector<std::pair<std::string, std::shared_ptr<const core::MapRayCaster>>> maps;
  for (const char* name : { "office", "warehouse" })
  {
    const std::string path = std::string(FDML_SOURCE_DIR) + "/maps/" + name + ".poly";
    maps.emplace_back(name, std::make_shared<const core::MapRayCaster>(core::loadPolyFile(path)));
  }
  core::BuildingOptions options;  // 60 m x 40 m
  maps.emplace_back("building60x40", std::make_shared<const core::MapRayCaster>(core::generateBuilding(options)));
  for (const auto& [name, caster] : maps)
  {
    for (const bool accelerated : { false, true })
    {
      for (const int threads : { 1, 2 })
      {
        const std::string label =
            "RayCast/" + name + (accelerated ? "/grid" : "/brute") + "/threads:" + std::to_string(threads);
        benchmark::RegisterBenchmark(label.c_str(), castBatch, caster, accelerated, threads)->UseRealTime();
      }
    }
    for (const double fov_deg : { 0.0, 2.0, 15.0, 27.0, 30.0 })
    {
      const std::string label = "ConeCast/" + name + "/fov_deg:" + std::to_string(static_cast<int>(fov_deg));
      benchmark::RegisterBenchmark(label.c_str(), coneBatch, caster, fov_deg)->UseRealTime();
    }
    for (const double fov_deg : { 0.0, 27.0 })
    {
      const std::string label = "ConePolish/" + name + "/fov_deg:" + std::to_string(static_cast<int>(fov_deg));
      benchmark::RegisterBenchmark(label.c_str(), polishBatch, caster, fov_deg)->UseRealTime();
    }
  }
}
}  // namespace

int main(int argc, char** argv)
{
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv))
  {
    return 1;
  }
  registerAll();
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
