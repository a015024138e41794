#include "fdml_localization/core/localization/voxel/distance_table.h"

#include "fdml_localization/core/util/threads.h"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace core
{
DistanceTable::DistanceTable(const GridSpec& spec, std::vector<float> values) : spec_(spec), values_(std::move(values))
{
  if (values_.size() != spec_.voxelCount())
  {
    throw std::invalid_argument("DistanceTable: " + std::to_string(values_.size()) + " values for a grid of " +
                                std::to_string(spec_.voxelCount()));
  }
  computeBlocks();
}

DistanceTable DistanceTable::build(const MapRayCaster& map, const GridSpec& spec, int threads)
{
  const int nx = spec.nx;
  const int ny = spec.ny;
  const int nt = spec.nt;
  std::vector<float> values(spec.voxelCount(), std::numeric_limits<float>::quiet_NaN());
  std::vector<Vec2> directions(nt);
  for (int it = 0; it < nt; ++it)
  {
    const double theta = spec.centreTheta(it);
    directions[it] = Vec2(std::cos(theta), std::sin(theta));
  }
  const std::size_t slice = static_cast<std::size_t>(nx) * ny;
  const long cells = static_cast<long>(slice);
#pragma omp parallel for schedule(dynamic, 16) num_threads(threadsFor(threads))
  for (long c = 0; c < cells; ++c)
  {
    const int ix = static_cast<int>(c % nx);
    const int iy = static_cast<int>(c / nx);
    const Vec2 origin(spec.centreX(ix), spec.centreY(iy));
    if (!map.isFree(origin))
    {
      continue;
    }
    for (int it = 0; it < nt; ++it)
    {
      const RayHit hit = map.cast(origin, directions[it]);
      values[static_cast<std::size_t>(it) * slice + static_cast<std::size_t>(c)] = static_cast<float>(hit.distance);
    }
  }
  return DistanceTable(spec, std::move(values));
}

void DistanceTable::computeBlocks()
{
  const int nx = spec_.nx;
  const int ny = spec_.ny;
  const int nt = spec_.nt;
  const float inf = std::numeric_limits<float>::infinity();
  const std::size_t slice = static_cast<std::size_t>(nx) * ny;
  // Min / max over 2 x 2 in (x, y) first, then over the theta pair.
  std::vector<float> lo2(values_.size(), inf);
  std::vector<float> hi2(values_.size(), -inf);
#pragma omp parallel for schedule(static)
  for (int it = 0; it < nt; ++it)
  {
    const float* v = values_.data() + it * slice;
    for (int iy = 0; iy + 1 < ny; ++iy)
    {
      const float* r0 = v + static_cast<std::size_t>(iy) * nx;
      const float* r1 = r0 + nx;
      float* lo = lo2.data() + it * slice + static_cast<std::size_t>(iy) * nx;
      float* hi = hi2.data() + it * slice + static_cast<std::size_t>(iy) * nx;
      for (int ix = 0; ix + 1 < nx; ++ix)
      {
        float mn = inf;
        float mx = -inf;
        const float s[4] = { r0[ix], r0[ix + 1], r1[ix], r1[ix + 1] };
        for (float x : s)
        {
          if (!std::isnan(x))
          {
            mn = std::min(mn, x);
            mx = std::max(mx, x);
          }
        }
        lo[ix] = mn;
        hi[ix] = mx;
      }
    }
  }
  steps_ = RangeSteps::covering({ &values_ });
  block_min_.resize(values_.size());
  block_max_.resize(values_.size());
#pragma omp parallel for schedule(static)
  for (int it = 0; it < nt; ++it)
  {
    const std::size_t a = it * slice;
    const std::size_t b = ((it + 1) % nt) * slice;
    for (std::size_t k = 0; k < slice; ++k)
    {
      block_min_[a + k] = steps_.down(std::min(lo2[a + k], lo2[b + k]));
      block_max_[a + k] = steps_.up(std::max(hi2[a + k], hi2[b + k]));
    }
  }
}

std::size_t DistanceTable::memoryBytes() const
{
  return values_.capacity() * sizeof(float) + (block_min_.capacity() + block_max_.capacity()) * sizeof(std::uint16_t);
}

}  // namespace core
}  // namespace fdml_localization
