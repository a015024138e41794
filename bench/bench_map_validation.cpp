// Map validation (issue 15 item 10): validateRings (SegmentBuckets, O(n log n)) against the
// previous check, Boost.Geometry's is_valid (test/common/ring_validation_reference.h), on one
// simple ring of n vertices: a circle of radius 100 m with 1 cm of radial noise.
#include "fdml_localization/core/map/polygon_map.h"
#include "ring_validation_reference.h"

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

namespace fdml_localization
{
namespace
{
core::Ring noisyCircle(int n)
{
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> radius(99.99, 100.0);
  core::Ring ring;
  for (int i = 0; i < n; ++i)
  {
    const double a = 2.0 * M_PI * i / n;
    const double r = radius(rng);
    ring.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return ring;
}

void BM_ValidateRings(benchmark::State& state)
{
  const std::vector<core::Ring> rings{ noisyCircle(static_cast<int>(state.range(0))) };
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(core::validateRings(rings));
  }
}
BENCHMARK(BM_ValidateRings)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_ValidateRingsBoostReference(benchmark::State& state)
{
  const std::vector<core::Ring> rings{ noisyCircle(static_cast<int>(state.range(0))) };
  for (auto _ : state)
  {
    benchmark::DoNotOptimize(core::test::referenceVerdict(rings));
  }
}
BENCHMARK(BM_ValidateRingsBoostReference)
    ->Arg(1000)
    ->Arg(10000)
    ->Arg(100000)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
}  // namespace
}  // namespace fdml_localization
