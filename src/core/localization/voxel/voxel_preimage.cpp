// The voxel engine's preimage test: voxel v is in reading i's preimage when the reading lies within
// the bounds of h (cell_bounds.h) over every sensor pose (v (+) g_i) can take, widened by tau.
#include "fdml_localization/core/localization/voxel/voxel_engine.h"

#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/voxel/row_marks.h"

#include <algorithm>
#include <cstddef>
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

/// The window arrays one slice of one reading reads, at its heading cells; x and y windows of two
/// cells start at dx0 + k (k < nwx) and dy0 + k relative to the voxel; window index = cell + 1.
struct SliceWindows
{
  int dx0 = 0;
  int nwx = 0;
  int dy0 = 0;
  int nwy = 0;
  const std::uint16_t* lower = nullptr;  ///< in range steps (RangeSteps), as the others
  const std::uint16_t* upper = nullptr;
  const std::uint16_t* inner = nullptr;  ///< cone readings only
};

struct RowBuffers
{
  explicit RowBuffers(int nx) : lo(nx), hi(nx), in(nx)
  {}
  std::vector<std::uint16_t> lo;
  std::vector<std::uint16_t> hi;
  std::vector<std::uint16_t> in;
};

/// Marks row iy: the bounds over the slice's windows (min of the lower, max of the upper bounds,
/// and for cones the min with the max of the inner upper bounds) against the reading's band.
template <class Plan>
void fillRow(const GridSpec& spec, const SliceWindows& w, const Plan& plan, int iy, RowBuffers& rows,
             std::uint64_t* out)
{
  const int nx = spec.nx;
  const std::size_t ny = static_cast<std::size_t>(spec.ny);
  if (w.nwx == 1 && w.nwy == 1 && !w.inner && w.dx0 + 1 >= 0)
  {
    // One window: read the arrays in place.
    const int wy = iy + w.dy0 + 1;
    const int shift = w.dx0 + 1;
    if (wy >= 0 && wy < spec.ny)
    {
      const std::size_t row = static_cast<std::size_t>(wy) * nx + shift;
      markRow(w.lower, w.upper, static_cast<std::ptrdiff_t>(row), 0, std::min(nx, nx - shift), plan.lo, plan.hi,
              plan.no_return, out);
    }
    return;
  }
  // The steps' ends stand for -inf and +inf (the identities of max and min).
  const std::uint16_t inf = RangeSteps::kLast;
  std::fill(rows.lo.begin(), rows.lo.end(), inf);
  std::fill(rows.hi.begin(), rows.hi.end(), 0);
  std::fill(rows.in.begin(), rows.in.end(), w.inner ? 0 : inf);
  for (int ky = 0; ky < w.nwy; ++ky)
  {
    const int wy = iy + w.dy0 + ky + 1;
    for (int kx = 0; kx < w.nwx && wy >= 0 && static_cast<std::size_t>(wy) < ny; ++kx)
    {
      const int shift = w.dx0 + kx + 1;  // window index wx = ix + shift
      const std::size_t row = static_cast<std::size_t>(wy) * nx + shift;
      for (int ix = std::max(0, -shift); ix < std::min(nx, nx - shift); ++ix)
      {
        rows.lo[ix] = std::min(rows.lo[ix], w.lower[row + ix]);
        rows.hi[ix] = std::max(rows.hi[ix], w.upper[row + ix]);
        rows.in[ix] = w.inner ? std::max(rows.in[ix], w.inner[row + ix]) : inf;
      }
    }
  }
  for (int ix = 0; ix < nx; ++ix)
  {
    rows.hi[ix] = std::min(rows.hi[ix], rows.in[ix]);
  }
  markRow(rows.lo.data(), rows.hi.data(), 0, 0, nx, plan.lo, plan.hi, plan.no_return, out);
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
  const std::uint16_t* bmin = table_.blockMin().data();
  const std::uint16_t* bmax = table_.blockMax().data();
  // The band's bottom rounded up and its top down, as the blocks' steps are.
  const std::uint16_t lo_steps = table_.steps().up(lo);
  const std::uint16_t hi_steps = table_.steps().down(hi);
  for (int iy = y_begin; iy < y_end; ++iy)
  {
    const std::ptrdiff_t base = static_cast<std::ptrdiff_t>(t0 * slice + static_cast<std::size_t>(iy + sy) * nx) + sx;
    markRow(bmin, bmax, base, x_begin, x_end, lo_steps, hi_steps, no_return, set.row(iy, it));
  }
}

bool VoxelEngine::preimagePlan(const Reading& reading, PreimagePlan& plan) const
{
  const double dt = spec_.thetaStep();
  const double tau = options_.range_tolerance;
  const bool no_return = !std::isfinite(reading.range);
  plan.no_return = no_return;
  // The band's bottom rounded up and its top down, as the windows' steps are (RangeSteps).
  plan.lo = windows_.steps().up(roundDown(no_return ? reading.max_range - tau : reading.range - tau));
  plan.hi = windows_.steps().down(roundUp(no_return ? kInf : reading.range + tau));
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
  // Sensor positions of voxel (ix, iy, it), in position-lattice units: within r of the centre's
  // (+) g, the arc of g over the voxel's headings being no longer than |g| dt / 2.
  const double theta = spec_.centreTheta(it);
  const double c = std::cos(theta);
  const double s = std::sin(theta);
  const double ox = (c * reading.offset.x - s * reading.offset.y) / spec_.cell;
  const double oy = (s * reading.offset.x + c * reading.offset.y) / spec_.cell;
  const double r = 0.5 * std::hypot(reading.offset.x, reading.offset.y) * spec_.thetaStep() / spec_.cell;
  SliceWindows w;
  const double limit = 4.0 * (spec_.nx + spec_.ny) + 8.0;
  if (!cellRange(ox - r - 0.5, ox + r + 0.5, limit, w.dx0, w.nwx) ||
      !cellRange(oy - r - 0.5, oy + r + 0.5, limit, w.dy0, w.nwy))
  {
    return;  // the sensor is nowhere near the grid for any voxel of this slice
  }
  // Windows of two cells starting at dx0 .. dx0 + nwx - 1 cover cells dx0 .. dx0 + nwx.
  w.nwx = std::max(1, w.nwx - 1);
  w.nwy = std::max(1, w.nwy - 1);
  const int nt = spec_.nt;
  auto wrapT = [nt](int t) { return ((t % nt) + nt) % nt; };
  w.lower = windows_.get(Kind::Lower, plan.lower.count).data() + spec_.index(0, 0, wrapT(it + plan.lower.first));
  w.upper = windows_.get(Kind::UpperMax, plan.ray.count).data() + spec_.index(0, 0, wrapT(it + plan.ray.first));
  if (plan.inner.count > 0)
  {
    w.inner = windows_.get(Kind::UpperInner, plan.inner.count).data() + spec_.index(0, 0, wrapT(it + plan.inner.first));
  }
  RowBuffers rows(spec_.nx);
  for (int iy = 0; iy < spec_.ny; ++iy)
  {
    fillRow(spec_, w, plan, iy, rows, set.row(iy, it));
  }
}

}  // namespace core
}  // namespace fdml_localization
