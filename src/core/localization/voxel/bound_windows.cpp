#include "fdml_localization/core/localization/voxel/bound_windows.h"

#include <algorithm>
#include <deque>
#include <limits>
#include <stdexcept>
#include <string>

namespace fdml_localization
{
namespace core
{
namespace
{
/// out[j] = op over in[j .. j + m - 1] (indices mod n), O(n) with a monotone deque.
template <class Better>
void slidingPeriodic(const std::vector<float>& in, int m, Better better, std::vector<float>& out)
{
  const int n = static_cast<int>(in.size());
  m = std::min(m, n);
  std::deque<int> window;
  for (int k = 0; k < n + m - 1; ++k)
  {
    const float v = in[k % n];
    while (!window.empty() && !better(in[window.back() % n], v))
    {
      window.pop_back();
    }
    window.push_back(k);
    if (window.front() <= k - m)
    {
      window.pop_front();
    }
    if (k >= m - 1)
    {
      out[k - m + 1] = in[window.front() % n];
    }
  }
}

/// Per padded cell column, the min (or max) over theta cells t .. t + m - 1, into @p along.
void alongTheta(const std::vector<float>& src, int nt, int m, bool theta_min, UninitialisedVector<float>& along)
{
  along.resize(src.size());
  const std::size_t pslice = src.size() / static_cast<std::size_t>(nt);
#pragma omp parallel
  {
    std::vector<float> in(nt);
    std::vector<float> out(nt);
#pragma omp for schedule(static)
    for (long c = 0; c < static_cast<long>(pslice); ++c)
    {
      for (int t = 0; t < nt; ++t)
      {
        in[t] = src[t * pslice + c];
      }
      if (theta_min)
      {
        slidingPeriodic(
            in, m, [](float a, float b) { return a < b; }, out);
      }
      else
      {
        slidingPeriodic(
            in, m, [](float a, float b) { return a > b; }, out);
      }
      for (int t = 0; t < nt; ++t)
      {
        along[t * pslice + c] = out[t];
      }
    }
  }
}

/// One row of windows: entry wx the min (lower) or max of padded cells wx and wx + 1 of rows @p r0
/// and @p r1 (heading-combined), in @p steps (lower bounds rounded down, upper ones up).
void windowRow(const float* r0, const float* r1, int nx, bool lower, const RangeSteps& steps, std::uint16_t* o)
{
  for (int wx = 0; wx < nx; ++wx)
  {
    o[wx] = lower ? steps.down(std::min({ r0[wx], r0[wx + 1], r1[wx], r1[wx + 1] })) :
                    steps.up(std::max({ r0[wx], r0[wx + 1], r1[wx], r1[wx + 1] }));
  }
}

/// Min (lower) or max over 2 x 2 padded cells: window (wx, wy) = cells (wx .. wx + 1, wy .. wy + 1)
/// (windowRow()).
UninitialisedVector<std::uint16_t> positionWindows(const UninitialisedVector<float>& along, const GridSpec& spec,
                                                   bool lower, const RangeSteps& steps)
{
  const int pnx = spec.nx + 1;
  const std::size_t pslice = static_cast<std::size_t>(pnx) * (spec.ny + 1);
  UninitialisedVector<std::uint16_t> result(spec.voxelCount());  // every entry written below
#pragma omp parallel for schedule(static)
  for (int t = 0; t < spec.nt; ++t)
  {
    for (int wy = 0; wy < spec.ny; ++wy)
    {
      const float* r0 = along.data() + t * pslice + static_cast<std::size_t>(wy) * pnx;
      windowRow(r0, r0 + pnx, spec.nx, lower, steps, result.data() + spec.index(0, wy, t));
    }
  }
  return result;
}
/// Windows of at most this many heading cells are combined row by row (shortWindows()).
constexpr int kShortWindow = 16;

/// positionWindows() of alongTheta() for a window of @p m <= kShortWindow heading cells, without
/// the array between them: each padded row's cells combined over the m heading slices (in order)
/// as it is needed (rays' windows are 2 cells).
UninitialisedVector<std::uint16_t> shortWindows(const std::vector<float>& src, const GridSpec& spec, int m,
                                                bool theta_min, bool lower, const RangeSteps& steps)
{
  const std::size_t pnx = static_cast<std::size_t>(spec.nx) + 1;
  const std::size_t pslice = pnx * (static_cast<std::size_t>(spec.ny) + 1);
  UninitialisedVector<std::uint16_t> result(spec.voxelCount());  // every entry written below
#pragma omp parallel
  {
    std::vector<float> near(pnx);
    std::vector<float> far(pnx);
    const auto combine = [&](int t, std::size_t row, std::vector<float>& out) {
      const float* first = src.data() + static_cast<std::size_t>(t) * pslice + row * pnx;
      std::copy_n(first, pnx, out.begin());
      for (int k = 1; k < m; ++k)
      {
        const float* in = src.data() + static_cast<std::size_t>((t + k) % spec.nt) * pslice + row * pnx;
        for (std::size_t c = 0; c < pnx; ++c)
        {
          out[c] = theta_min ? std::min(out[c], in[c]) : std::max(out[c], in[c]);
        }
      }
    };
#pragma omp for schedule(static)
    for (int t = 0; t < spec.nt; ++t)
    {
      combine(t, 0, far);
      for (int wy = 0; wy < spec.ny; ++wy)
      {
        near.swap(far);
        combine(t, static_cast<std::size_t>(wy) + 1, far);
        windowRow(near.data(), far.data(), spec.nx, lower, steps, result.data() + spec.index(0, wy, t));
      }
    }
  }
  return result;
}
}  // namespace

BoundWindows::BoundWindows(CellBounds cells)
  : cells_(std::move(cells)), steps_(RangeSteps::covering({ &cells_.lower(), &cells_.upper() }))
{}

void BoundWindows::require(Kind kind, int m)
{
  const auto key = std::make_pair(static_cast<int>(kind), m);
  if (arrays_.count(key) == 0)
  {
    const bool lower = kind == Kind::Lower;
    const std::vector<float>& bounds = lower ? cells_.lower() : cells_.upper();
    if (std::min(m, cells_.spec().nt) <= kShortWindow)
    {
      arrays_.emplace(key, shortWindows(bounds, cells_.spec(), std::max(1, std::min(m, cells_.spec().nt)),
                                        kind != Kind::UpperMax, lower, steps_));
      return;
    }
    alongTheta(bounds, cells_.spec().nt, m, kind != Kind::UpperMax, along_);
    arrays_.emplace(key, positionWindows(along_, cells_.spec(), lower, steps_));
  }
}

const UninitialisedVector<std::uint16_t>& BoundWindows::get(Kind kind, int m) const
{
  const auto it = arrays_.find(std::make_pair(static_cast<int>(kind), m));
  if (it == arrays_.end())
  {
    throw std::logic_error("BoundWindows: window " + std::to_string(m) + " was not prepared");
  }
  return it->second;
}

std::size_t BoundWindows::memoryBytes() const
{
  std::size_t total = cells_.memoryBytes() + along_.capacity() * sizeof(float);
  for (const auto& [key, a] : arrays_)
  {
    total += a.capacity() * sizeof(std::uint16_t);
  }
  return total;
}

}  // namespace core
}  // namespace fdml_localization
