#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/util/stopwatch.h"

#include <omp.h>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{

/// Where rays hit near a concave corner, h is the minimum of two linear pieces and peaks between
/// samples, above all of them, by up to about the slope difference times half a cell: the band
/// [d - tau, d + tau] is widened by this many cells so the truth's voxel stays in its preimage.
constexpr double kKinkMargin = 0.5;

int floorDiv(double value)
{
  return static_cast<int>(std::floor(value));
}

/// Sets bit ix of @p row for ix in [begin, end) when [rmin[ix], rmax[ix]] meets [lo, hi]
/// (no_return: when rmax[ix] >= lo).
void markRow(const float* rmin, const float* rmax, int begin, int end, float lo, float hi, bool no_return,
             std::uint64_t* row)
{
  auto scalar = [&](int ix) {
    const bool in = no_return ? rmax[ix] >= lo : (rmin[ix] <= hi && rmax[ix] >= lo);
    row[ix >> 6] |= static_cast<std::uint64_t>(in) << (ix & 63);
  };
  int ix = begin;
#ifdef __SSE2__
  for (; ix < end && (ix & 3) != 0; ++ix)
  {
    scalar(ix);
  }
  // Four voxels per step; an aligned group of four never straddles two words.
  const __m128 vlo = _mm_set1_ps(lo);
  const __m128 vhi = _mm_set1_ps(no_return ? std::numeric_limits<float>::infinity() : hi);
  for (; ix + 4 <= end; ix += 4)
  {
    const __m128 below = _mm_cmple_ps(_mm_loadu_ps(rmin + ix), vhi);
    const __m128 in = _mm_and_ps(below, _mm_cmpge_ps(_mm_loadu_ps(rmax + ix), vlo));
    row[ix >> 6] |= static_cast<std::uint64_t>(_mm_movemask_ps(in)) << (ix & 63);
  }
#endif
  for (; ix < end; ++ix)
  {
    scalar(ix);
  }
}

/// byte_spread[b] has byte j = bit j of b: adds 8 voxels' bits to 8 count bytes at once.
struct ByteSpread
{
  std::uint64_t table[256];
  ByteSpread()
  {
    for (int b = 0; b < 256; ++b)
    {
      std::uint64_t v = 0;
      for (int j = 0; j < 8; ++j)
      {
        v |= static_cast<std::uint64_t>((b >> j) & 1) << (8 * j);
      }
      table[b] = v;
    }
  }
};
const ByteSpread kByteSpread;
}  // namespace

VoxelEngine::VoxelEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options)
  : map_(std::move(map)), options_(options)
{
  if (!map_)
  {
    throw std::invalid_argument("VoxelEngine: no map");
  }
  spec_ = GridSpec::fromMap(map_->map(), options_.resolution, options_.theta_resolution);
}

int VoxelEngine::threads() const
{
  return options_.threads > 0 ? options_.threads : omp_get_max_threads();
}

void VoxelEngine::prepare()
{
  if (prepared_)
  {
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  table_ = loadOrBuildTable(*map_, spec_, options_.cache_dir, threads(), &table_source_, &cache_message_);
  prepared_ = true;
  prepare_seconds_ = secondsSince(start);
}

const DistanceTable& VoxelEngine::table()
{
  prepare();
  return table_;
}

void VoxelEngine::fillPreimageSlice(const Reading& reading, int it, VoxelSet& set) const
{
  const int nx = spec_.nx;
  const int ny = spec_.ny;
  const int nt = spec_.nt;
  const bool no_return = !std::isfinite(reading.range);
  const double band = preimageBand();
  const float lo = static_cast<float>(no_return ? reading.max_range - band : reading.range - band);
  const float hi = static_cast<float>(reading.range + band);
  const std::size_t slice = static_cast<std::size_t>(nx) * ny;
  const double theta = spec_.centreTheta(it);
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  // (centre of voxel (ix, iy, it)) (+) g sits at sample-lattice coordinate (ix + ox / cell, ...):
  // the same shift for the whole slice, so its sample block starts at (ix + sx, iy + sy, t0).
  const double ox = c * reading.offset.x - s * reading.offset.y;
  const double oy = s * reading.offset.x + c * reading.offset.y;
  // A point exactly on a sample (g = 0, the first reading of a batch) takes the block that
  // starts there, whatever the rounding of the lattice coordinate: hence the 1e-9.
  const int sx = floorDiv(ox / spec_.cell + 1e-9);
  const int sy = floorDiv(oy / spec_.cell + 1e-9);
  const double phi = wrapAngle(theta + reading.offset.theta);
  int t0 = floorDiv((phi + kPi) / spec_.thetaStep() - 0.5 + 1e-9) % nt;
  t0 = t0 < 0 ? t0 + nt : t0;
  // Blocks start at samples xx in [0, nx - 2] and yy in [0, ny - 2].
  const int x_begin = std::max(0, -sx);
  const int x_end = std::min(nx, nx - 1 - sx);
  const int y_begin = std::max(0, -sy);
  const int y_end = std::min(ny, ny - 1 - sy);
  const float* bmin = table_.blockMin().data();
  const float* bmax = table_.blockMax().data();
  for (int iy = y_begin; iy < y_end; ++iy)
  {
    const std::size_t base = static_cast<std::size_t>(t0) * slice + static_cast<std::size_t>(iy + sy) * nx + sx;
    markRow(bmin + base, bmax + base, x_begin, x_end, lo, hi, no_return, set.row(iy, it));
  }
}

double VoxelEngine::preimageBand() const
{
  return options_.range_tolerance + kKinkMargin * spec_.cell;
}

VoxelSet VoxelEngine::rawPreimage(const Reading& reading)
{
  prepare();
  VoxelSet set(spec_);
#pragma omp parallel for schedule(static) num_threads(threads())
  for (int it = 0; it < spec_.nt; ++it)
  {
    fillPreimageSlice(reading, it, set);
  }
  return set;
}

std::vector<VoxelSet> VoxelEngine::preimages(const std::vector<Reading>& readings)
{
  std::vector<VoxelSet> raw;
  return preimages(readings, raw);
}

std::vector<VoxelSet> VoxelEngine::preimages(const std::vector<Reading>& readings, std::vector<VoxelSet>& raw)
{
  prepare();
  const long k = static_cast<long>(readings.size());
  const long nt = spec_.nt;
  raw.assign(readings.size(), VoxelSet(spec_));
  std::vector<VoxelSet> sets(readings.size());
#pragma omp parallel num_threads(threads())
  {
#pragma omp for schedule(static)
    for (long job = 0; job < k * nt; ++job)
    {
      fillPreimageSlice(readings[job / nt], static_cast<int>(job % nt), raw[job / nt]);
    }
#pragma omp for schedule(dynamic, 1)
    for (long i = 0; i < k; ++i)
    {
      sets[i] = raw[i].dilated();
    }
  }
  return sets;
}

void VoxelEngine::countField(const std::vector<VoxelSet>& sets, std::vector<std::uint8_t>& count) const
{
  count.assign(spec_.voxelCount(), 0);
  const int nx = spec_.nx;
  const int ny = spec_.ny;
  const int nt = spec_.nt;
#pragma omp parallel for schedule(static) num_threads(threads())
  for (int it = 0; it < nt; ++it)
  {
    for (const VoxelSet& set : sets)
    {
      for (int iy = 0; iy < ny; ++iy)
      {
        const std::uint64_t* row = set.row(iy, it);
        std::uint8_t* out = count.data() + spec_.index(0, iy, it);
        for (int k = 0; k < set.wordsPerRow(); ++k)
        {
          const std::uint64_t w = row[k];
          if (w == 0)
          {
            continue;
          }
          for (int j = 0; j < 8; ++j)
          {
            const auto byte = static_cast<unsigned>((w >> (8 * j)) & 0xffu);
            const int ix = 64 * k + 8 * j;
            if (byte == 0)
            {
              continue;
            }
            if (ix + 8 <= nx)
            {
              // Eight counts at once: no byte overflows (at most 255 sets).
              std::uint64_t eight = 0;
              std::memcpy(&eight, out + ix, 8);
              eight += kByteSpread.table[byte];
              std::memcpy(out + ix, &eight, 8);
            }
            else
            {
              for (int b = 0; b < 8 && ix + b < nx; ++b)
              {
                out[ix + b] = static_cast<std::uint8_t>(out[ix + b] + ((byte >> b) & 1u));
              }
            }
          }
        }
      }
    }
  }
}

std::vector<bool> VoxelEngine::membership(std::size_t voxel, const std::vector<VoxelSet>& sets) const
{
  int ix = 0;
  int iy = 0;
  int it = 0;
  spec_.unindex(voxel, ix, iy, it);
  std::vector<bool> in(sets.size(), false);
  for (std::size_t i = 0; i < sets.size(); ++i)
  {
    in[i] = sets[i].test(ix, iy, it);
  }
  return in;
}

Result VoxelEngine::localize(const std::vector<Reading>& readings)
{
  const auto start = std::chrono::steady_clock::now();
  Result result;
  result.engine = Engine::Voxel;
  result.method = options_.method;
  result.readings_used = static_cast<int>(readings.size());
  prepare();
  if (!prepare_reported_)
  {
    result.times.table = prepare_seconds_;
    prepare_reported_ = true;
  }

  auto stage = std::chrono::steady_clock::now();
  sets_ = preimages(readings, raw_sets_);
  result.times.preimages = secondsSince(stage);

  stage = std::chrono::steady_clock::now();
  countField(sets_, count_);
  if (options_.method == Method::Robust)
  {
    countField(raw_sets_, raw_count_);
  }
  result.times.count = secondsSince(stage);

  const int k = static_cast<int>(readings.size());
  switch (options_.method)
  {
    case Method::Robust:
      localizeRobust(readings, result);
      break;
    case Method::Paper:
      localizeComponentCentres(readings, options_.min_inliers, result);
      break;
    case Method::Baseline:
      localizeComponentCentres(readings, k, result);
      break;
  }
  result.times.total = secondsSince(start);
  return result;
}

}  // namespace core
}  // namespace fdml_localization
