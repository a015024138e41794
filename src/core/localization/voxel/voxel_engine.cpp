#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/components.h"
#include "fdml_localization/core/localization/voxel/box_occupancy.h"
#include "fdml_localization/core/util/stopwatch.h"

#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iterator>
#include <limits>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{

/// byte_spread[b] has byte j = bit j of b: spreads 8 voxels' bits to 8 count bytes at once.
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

/**
 * @brief Writes to out[0, n) how many of @p rows hold each of the 64 voxels of their word @p w:
 *        the counts are added bit-sliced (plane b holds bit b of every voxel's count; @p used
 *        planes, enough for rows.size() <= 255), then spread to bytes eight voxels at a time.
 *        Every row ripples through all planes: a carry chain ending where the data says would
 *        mispredict a branch per row.
 */
void writeWordCounts(const std::vector<const std::uint64_t*>& rows, int w, int used, std::uint8_t* out, int n)
{
  std::uint64_t planes[8] = {};
  std::uint64_t any = 0;
  for (const std::uint64_t* row : rows)
  {
    std::uint64_t x = row[w];
    any |= x;
    for (int b = 0; b < used; ++b)
    {
      const std::uint64_t carry = planes[b] & x;
      planes[b] ^= x;
      x = carry;
    }
  }
  if (any == 0)
  {
    std::memset(out, 0, static_cast<std::size_t>(n));
    return;
  }
  for (int j = 0; 8 * j < n; ++j)
  {
    std::uint64_t eight = 0;
    for (int b = 0; b < used; ++b)
    {
      eight += kByteSpread.table[(planes[b] >> (8 * j)) & 0xffu] << b;
    }
    std::memcpy(out + 8 * j, &eight, static_cast<std::size_t>(std::min(8, n - 8 * j)));
  }
}

/// The voxels whose cell may meet @p region, every heading (conservative: a "no" is exact).
VoxelSet regionMask(const MapRayCaster& region, const GridSpec& spec)
{
  const BoxOccupancy occupancy(region, spec.cell);  // a voxel's cell is one query
  VoxelSet mask(spec);
  for (int iy = 0; iy < spec.ny; ++iy)
  {
    for (int ix = 0; ix < spec.nx; ++ix)
    {
      Box2 cell;
      cell.extend(Vec2(spec.origin_x + ix * spec.cell, spec.origin_y + iy * spec.cell));
      cell.extend(Vec2(spec.origin_x + (ix + 1) * spec.cell, spec.origin_y + (iy + 1) * spec.cell));
      const bool inside = occupancy.mayBeFree(cell);
      for (int it = 0; inside && it < spec.nt; ++it)
      {
        mask.set(ix, iy, it);
      }
    }
  }
  return mask;
}
}  // namespace

VoxelEngine::VoxelEngine(std::shared_ptr<const MapRayCaster> map, const LocalizerOptions& options)
  : map_(std::move(map)), options_(options)
{
  if (!map_)
  {
    throw std::invalid_argument("VoxelEngine: no map");
  }
  if (map_->map().empty() || !(map_->map().area() > 0.0))
  {
    throw std::invalid_argument("the map has no area");
  }
  spec_ = GridSpec::fromBounds(searchBounds(*map_, options_), options_.resolution, options_.theta_resolution);
}

int VoxelEngine::threads() const
{
  return threadsFor(options_.threads);
}

void VoxelEngine::prepare()
{
  if (prepared_)
  {
    return;
  }
  const auto start = std::chrono::steady_clock::now();
  table_ = loadOrBuildTable(*map_, spec_, options_.cache_dir, threads(), &table_source_, &cache_message_);
  windows_ = BoundWindows(CellBounds::compute(*map_, spec_, threads()));
  if (options_.search_region)
  {
    region_mask_ = regionMask(*options_.search_region, spec_);
  }
  prepared_ = true;
  prepare_seconds_ = secondsSince(start);
}

const DistanceTable& VoxelEngine::table()
{
  prepare();
  return table_;
}

double VoxelEngine::preimageBand() const
{
  return options_.range_tolerance;
}

VoxelSet VoxelEngine::rawPreimage(const Reading& reading)
{
  prepare();
  prepareWindows({ reading });
  VoxelSet set(spec_);
#pragma omp parallel for schedule(static) num_threads(threads())
  for (int it = 0; it < spec_.nt; ++it)
  {
    fillPreimageSlice(reading, it, set);
  }
  keepRegion(set);
  return set;
}

void VoxelEngine::keepRegion(VoxelSet& set) const
{
  if (!region_mask_.words().empty())
  {
    set &= region_mask_;
  }
}

std::vector<VoxelSet> VoxelEngine::preimages(const std::vector<Reading>& readings)
{
  std::vector<VoxelSet> raw;
  return preimages(readings, raw);
}

std::vector<VoxelSet> VoxelEngine::preimages(const std::vector<Reading>& readings, std::vector<VoxelSet>& raw)
{
  std::vector<VoxelSet> sets;
  preimagesInto(readings, sets, raw);
  return sets;
}

void VoxelEngine::preimagesInto(const std::vector<Reading>& readings, std::vector<VoxelSet>& sets,
                                std::vector<VoxelSet>& raw)
{
  prepare();
  prepareWindows(readings);
  const long k = static_cast<long>(readings.size());
  const long nt = spec_.nt;
  for (std::vector<VoxelSet>* v : { &sets, &raw })
  {
    v->resize(readings.size());
    for (VoxelSet& set : *v)
    {
      set.reshape(spec_);  // storage kept from the last batch; each slice cleared below
    }
  }
#pragma omp parallel for schedule(static) num_threads(threads())
  for (long job = 0; job < k * nt; ++job)
  {
    const Reading& r = readings[job / nt];
    const int it = static_cast<int>(job % nt);
    sets[job / nt].clearSlice(it);
    raw[job / nt].clearSlice(it);
    fillPreimageSlice(r, it, sets[job / nt]);
    if (!(r.half_angle > 0.0))
    {
      fillSampleSlice(r, it, raw[job / nt]);
    }
  }
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    keepRegion(sets[i]);
    keepRegion(raw[i]);
    if (readings[i].half_angle > 0.0)
    {
      raw[i] = sets[i];
    }
  }
}

std::vector<VoxelSet> VoxelEngine::paperPreimages(const std::vector<Reading>& readings)
{
  prepare();
  // The sample test is for rays: a cone reading's sample set is its conservative preimage (as
  // in preimages()), which needs its bound windows.
  std::vector<Reading> cones;
  std::copy_if(readings.begin(), readings.end(), std::back_inserter(cones),
               [](const Reading& r) { return r.half_angle > 0.0; });
  prepareWindows(cones);
  const long k = static_cast<long>(readings.size());
  const long nt = spec_.nt;
  std::vector<VoxelSet> raw(readings.size(), VoxelSet(spec_));
  std::vector<VoxelSet> sets(readings.size());
#pragma omp parallel num_threads(threads())
  {
#pragma omp for schedule(static)
    for (long job = 0; job < k * nt; ++job)
    {
      const Reading& r = readings[job / nt];
      if (r.half_angle > 0.0)
      {
        fillPreimageSlice(r, static_cast<int>(job % nt), raw[job / nt]);
      }
      else
      {
        fillSampleSlice(r, static_cast<int>(job % nt), raw[job / nt]);
      }
    }
#pragma omp for schedule(dynamic, 1)
    for (long i = 0; i < k; ++i)
    {
      sets[i] = raw[i].dilated();
      keepRegion(sets[i]);
    }
  }
  return sets;
}

void VoxelEngine::countField(const std::vector<VoxelSet>& sets, std::vector<std::uint8_t>& count) const
{
  if (sets.empty())
  {
    count.assign(spec_.voxelCount(), 0);
    return;
  }
  count.resize(spec_.voxelCount());  // every voxel is written below
  const int nx = spec_.nx;
  const int ny = spec_.ny;
  const int nt = spec_.nt;
  const int words = sets.front().wordsPerRow();
  int used = 1;  // bit planes holding counts up to sets.size() (at most 255 readings)
  while (used < 8 && (std::size_t{ 1 } << used) <= sets.size())
  {
    ++used;
  }
#pragma omp parallel for schedule(static) num_threads(threads())
  for (int it = 0; it < nt; ++it)
  {
    std::vector<const std::uint64_t*> rows(sets.size());
    for (int iy = 0; iy < ny; ++iy)
    {
      for (std::size_t i = 0; i < sets.size(); ++i)
      {
        rows[i] = sets[i].row(iy, it);
      }
      std::uint8_t* out = count.data() + spec_.index(0, iy, it);
      for (int w = 0; w < words; ++w)
      {
        writeWordCounts(rows, w, used, out + 64 * w, std::min(64, nx - 64 * w));
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
  if (options_.method == Method::Robust)
  {
    preimagesInto(readings, sets_, raw_sets_);
  }
  else
  {
    sets_ = paperPreimages(readings);
    raw_sets_.clear();
  }
  result.times.preimages = secondsSince(stage);

  stage = std::chrono::steady_clock::now();
  countField(sets_, count_);
  if (options_.method == Method::Robust)
  {
    countField(raw_sets_, raw_count_);
    seed_sets_.resize(raw_sets_.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads())
    for (long i = 0; i < static_cast<long>(raw_sets_.size()); ++i)
    {
      raw_sets_[i].dilateInto(seed_sets_[i]);
    }
    countField(seed_sets_, seed_count_);
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
