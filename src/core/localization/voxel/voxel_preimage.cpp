// The voxel engine's preimage test: voxel v is in reading i's preimage when the reading lies within
// the bounds of h (cell_bounds.h) over every sensor pose (v (+) g_i) can take, widened by tau.
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "fdml_localization/core/geometry/cone_cast.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace core
{
namespace
{
using Kind = BoundWindows::Kind;
constexpr double kEps = 1e-9;  ///< cells: lattice coordinates are widened by this before rounding
/// Seeding's sample test: where rays hit near a concave corner h peaks between samples by up to
/// about half a cell times the slope difference, so its band is widened by this many cells.
constexpr double kKinkMargin = 0.5;

float roundDown(double value)
{
  const float f = static_cast<float>(value);
  return static_cast<double>(f) > value ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}

float roundUp(double value)
{
  const float f = static_cast<float>(value);
  return static_cast<double>(f) < value ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
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

/// Cells [first, first + count) (lattice units, relative) covering [a, b] widened by kEps.
bool cellRange(double a, double b, double limit, int& first, int& count)
{
  int last = 0;
  if (!floorIndex(a - kEps, limit, first) || !floorIndex(b + kEps, limit, last))
  {
    return false;
  }
  count = last - first + 1;
  return true;
}
}  // namespace

void VoxelEngine::fillSampleSlice(const Reading& reading, int it, VoxelSet& set) const
{
  const int nx = spec_.nx;
  const int ny = spec_.ny;
  const int nt = spec_.nt;
  const bool no_return = !std::isfinite(reading.range);
  const double band = options_.range_tolerance + kKinkMargin * spec_.cell;
  const float lo = static_cast<float>(no_return ? reading.max_range - band : reading.range - band);
  const float hi = static_cast<float>(reading.range + band);
  const std::size_t slice = static_cast<std::size_t>(nx) * ny;
  const double theta = spec_.centreTheta(it);
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  // (centre of voxel (ix, iy, it)) (+) g sits at sample-lattice coordinate (ix + ox / cell, ...):
  // the same shift for the whole slice, so its sample block starts at (ix + sx, iy + sy, t0). A
  // point exactly on a sample takes the block that starts there: hence the 1e-9.
  const double ox = c * reading.offset.x - s * reading.offset.y;
  const double oy = s * reading.offset.x + c * reading.offset.y;
  const double limit = 4.0 * (nx + ny) + 8.0;
  int sx = 0;
  int sy = 0;
  int t0 = 0;
  if (!floorIndex(ox / spec_.cell + kEps, limit, sx) || !floorIndex(oy / spec_.cell + kEps, limit, sy) ||
      !floorIndex((wrapAngle(theta + reading.offset.theta) + kPi) / spec_.thetaStep() - 0.5 + kEps, 4.0 * nt, t0))
  {
    return;  // the sensor is nowhere near the grid
  }
  t0 = ((t0 % nt) + nt) % nt;
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

bool VoxelEngine::preimagePlan(const Reading& reading, PreimagePlan& plan) const
{
  const double dt = spec_.thetaStep();
  const double tau = options_.range_tolerance;
  const bool no_return = !std::isfinite(reading.range);
  plan.no_return = no_return;
  plan.lo = roundDown(no_return ? reading.max_range - tau : reading.range - tau);
  plan.hi = roundUp(no_return ? kInf : reading.range + tau);
  if (!std::isfinite(reading.offset.x) || !std::isfinite(reading.offset.y) || !std::isfinite(reading.offset.theta))
  {
    return false;
  }
  // Sensor headings of voxel it, in heading-lattice units: [it + s, it + s + 1].
  const double s = wrapAngle(reading.offset.theta) / dt - 0.5;
  const double limit = 4.0 * spec_.nt + 8.0;
  int first = 0;
  int count = 0;
  if (!cellRange(s, s + 1.0, limit, first, count))
  {
    return false;
  }
  plan.ray = ThetaWindow{ first, std::min(count, spec_.nt) };
  plan.lower = plan.ray;
  plan.inner = ThetaWindow{ 0, 0 };
  const double a = std::min(reading.half_angle, kMaxConeHalfAngle) / dt;
  if (a > 0.0)
  {
    if (!cellRange(s - a, s + 1.0 + a, limit, first, count))
    {
      return false;
    }
    plan.lower = ThetaWindow{ first, std::min(count, spec_.nt) };
    // Cells inside every heading window [psi - a, psi + a], psi in [s, s + 1]: [s + 1 - a, s + a].
    int inner_first = 0;
    int inner_end = 0;
    if (floorIndex(-(s + 1.0 - a + kEps), limit, inner_first) && floorIndex(s + a - kEps, limit, inner_end))
    {
      inner_first = -inner_first;  // ceil
      plan.inner = ThetaWindow{ inner_first, std::min(inner_end - inner_first, spec_.nt) };
    }
  }
  return true;
}

void VoxelEngine::prepareWindows(const std::vector<Reading>& readings)
{
  for (const Reading& r : readings)
  {
    PreimagePlan plan;
    if (preimagePlan(r, plan))
    {
      windows_.require(Kind::Lower, plan.lower.count);
      windows_.require(Kind::UpperMax, plan.ray.count);
      if (plan.inner.count > 0)
      {
        windows_.require(Kind::UpperInner, plan.inner.count);
      }
    }
  }
}

void VoxelEngine::fillPreimageSlice(const Reading& reading, int it, VoxelSet& set) const
{
  PreimagePlan plan;
  if (!preimagePlan(reading, plan))
  {
    return;
  }
  const int nx = spec_.nx;
  const int ny = spec_.ny;
  const int nt = spec_.nt;
  // Sensor positions of voxel (ix, iy, it), in position-lattice units: within r of the centre's
  // (+) g, the arc of g over the voxel's headings being no longer than |g| dt / 2.
  const double theta = spec_.centreTheta(it);
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double ox = (c * reading.offset.x - s * reading.offset.y) / spec_.cell;
  const double oy = (s * reading.offset.x + c * reading.offset.y) / spec_.cell;
  const double r = 0.5 * std::hypot(reading.offset.x, reading.offset.y) * spec_.thetaStep() / spec_.cell;
  int dx0 = 0;
  int nwx = 0;
  int dy0 = 0;
  int nwy = 0;
  const double limit = 4.0 * (nx + ny) + 8.0;
  if (!cellRange(ox - r - 0.5, ox + r + 0.5, limit, dx0, nwx) ||
      !cellRange(oy - r - 0.5, oy + r + 0.5, limit, dy0, nwy))
  {
    return;  // the sensor is nowhere near the grid for any voxel of this slice
  }
  // Windows of two cells starting at dx0 .. dx0 + nwx - 1 cover cells dx0 .. dx0 + nwx; window
  // index = first cell + 1.
  nwx = std::max(1, nwx - 1);
  nwy = std::max(1, nwy - 1);
  auto wrapT = [nt](int t) { return ((t % nt) + nt) % nt; };
  const float* lower = windows_.get(Kind::Lower, plan.lower.count).data();
  const float* upper = windows_.get(Kind::UpperMax, plan.ray.count).data();
  const float* inner = plan.inner.count > 0 ? windows_.get(Kind::UpperInner, plan.inner.count).data() : nullptr;
  const int t_lower = wrapT(it + plan.lower.first);
  const int t_upper = wrapT(it + plan.ray.first);
  const int t_inner = wrapT(it + plan.inner.first);
  std::vector<float> rlo(nx);
  std::vector<float> rhi(nx);
  std::vector<float> rin(nx);
  for (int iy = 0; iy < ny; ++iy)
  {
    std::fill(rlo.begin(), rlo.end(), std::numeric_limits<float>::infinity());
    std::fill(rhi.begin(), rhi.end(), -std::numeric_limits<float>::infinity());
    std::fill(rin.begin(), rin.end(), -std::numeric_limits<float>::infinity());
    bool any = false;
    for (int ky = 0; ky < nwy; ++ky)
    {
      const int wy = iy + dy0 + ky + 1;
      if (wy < 0 || wy >= ny)
      {
        continue;
      }
      for (int kx = 0; kx < nwx; ++kx)
      {
        const int shift = dx0 + kx + 1;  // window index wx = ix + shift
        const int begin = std::max(0, -shift);
        const int end = std::min(nx, nx - shift);
        const float* lo = lower + spec_.index(0, wy, t_lower) + shift;
        const float* hi = upper + spec_.index(0, wy, t_upper) + shift;
        const float* in = inner ? inner + spec_.index(0, wy, t_inner) + shift : nullptr;
        for (int ix = begin; ix < end; ++ix)
        {
          rlo[ix] = std::min(rlo[ix], lo[ix]);
          rhi[ix] = std::max(rhi[ix], hi[ix]);
          rin[ix] = in ? std::max(rin[ix], in[ix]) : std::numeric_limits<float>::infinity();
        }
        any = any || begin < end;
      }
    }
    if (!any)
    {
      continue;
    }
    for (int ix = 0; ix < nx; ++ix)
    {
      rhi[ix] = std::min(rhi[ix], rin[ix]);
    }
    markRow(rlo.data(), rhi.data(), 0, nx, plan.lo, plan.hi, plan.no_return, set.row(iy, it));
  }
}

}  // namespace core
}  // namespace fdml_localization
