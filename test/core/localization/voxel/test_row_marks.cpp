// The row tests of the preimages (row_marks.h) against a plain loop, on random bounds with rows
// starting and ending anywhere (the vector kernels' aligned groups and the scalar edges), and
// the range steps (RangeSteps): the quantised test marks every voxel the float test marks.
#include "fdml_localization/core/localization/voxel/row_marks.h"

#include "fdml_localization/core/localization/voxel/bound_windows.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace
{
/// The row markRow() should give, by a plain loop.
template <class T>
std::vector<std::uint64_t> plainRow(const std::vector<T>& rmin, const std::vector<T>& rmax, int shift, int begin,
                                    int end, T lo, T hi, bool no_return, std::size_t words)
{
  std::vector<std::uint64_t> row(words, 0);
  for (int ix = begin; ix < end; ++ix)
  {
    const T a = rmin[static_cast<std::size_t>(ix + shift)];
    const T b = rmax[static_cast<std::size_t>(ix + shift)];
    if (no_return ? b >= lo : (a <= hi && b >= lo))
    {
      row[static_cast<std::size_t>(ix) / 64] |= std::uint64_t{ 1 } << (ix % 64);
    }
  }
  return row;
}

template <class T, class Draw>
void expectRowsMatch(std::mt19937_64& rng, Draw draw)
{
  for (int trial = 0; trial < 3000; ++trial)
  {
    const int nx = 1 + static_cast<int>(rng() % 200);
    const int shift = static_cast<int>(rng() % 5);
    std::vector<T> rmin(static_cast<std::size_t>(nx + shift));
    std::vector<T> rmax(rmin.size());
    for (std::size_t i = 0; i < rmin.size(); ++i)
    {
      rmin[i] = draw();
      rmax[i] = draw();
    }
    const int begin = static_cast<int>(rng() % static_cast<unsigned>(nx));
    const int end = begin + static_cast<int>(rng() % static_cast<unsigned>(nx - begin + 1));
    const T lo = draw();
    const T hi = draw();
    const bool no_return = trial % 5 == 0;
    const std::size_t words = static_cast<std::size_t>((nx + 63) / 64);
    std::vector<std::uint64_t> row(words, 0);
    markRow(rmin.data(), rmax.data(), shift, begin, end, lo, hi, no_return, row.data());
    ASSERT_EQ(row, plainRow(rmin, rmax, shift, begin, end, lo, hi, no_return, words))
        << "nx " << nx << " [" << begin << ", " << end << ") shift " << shift;
  }
}

TEST(RowMarks, KernelsMatchAPlainLoop)
{
  std::mt19937_64 rng(41);
  // Few distinct values: ties between bounds and band are frequent.
  expectRowsMatch<float>(rng, [&] {
    const int v = static_cast<int>(rng() % 12);
    return v == 11 ? std::numeric_limits<float>::infinity() : 0.5f * static_cast<float>(v);
  });
  expectRowsMatch<std::uint16_t>(rng, [&] {
    const unsigned v = static_cast<unsigned>(rng() % 12);
    // The steps' ends and values across the top bit (unsigned order).
    return static_cast<std::uint16_t>(v == 11 ? 65535u : v == 10 ? 32768u : v == 9 ? 32767u : 1000u * v);
  });
}

TEST(RowMarks, RangeStepsKeepEveryVoxelTheFloatTestKeeps)
{
  std::mt19937_64 rng(43);
  std::uniform_real_distribution<double> range(-1.0, 40.0);
  const RangeSteps steps = RangeSteps::covering(35.0);
  int kept = 0;
  for (int trial = 0; trial < 200000; ++trial)
  {
    // Lower and upper bounds, a band; near-ties drawn often (within a step).
    const float inf = std::numeric_limits<float>::infinity();
    const float l = trial % 11 == 0 ? inf : static_cast<float>(range(rng));
    const float u = trial % 7 == 0 ? inf : trial % 13 == 0 ? -inf : static_cast<float>(range(rng));
    const float lo = trial % 3 == 0 ? u - static_cast<float>(1e-4 * (rng() % 10)) : static_cast<float>(range(rng));
    const float hi = trial % 3 == 1 ? l + static_cast<float>(1e-4 * (rng() % 10)) : static_cast<float>(range(rng));
    if (l <= hi && u >= lo)  // every voxel the float test keeps ...
    {
      ++kept;
      ASSERT_LE(steps.down(l), steps.down(hi)) << l << " " << hi;
      ASSERT_GE(steps.up(u), steps.up(lo)) << u << " " << lo;
    }
    // An infinite bound the float test rejects against a finite band stays rejected.
    if (l == inf && std::isfinite(hi))
    {
      EXPECT_GT(steps.down(l), steps.down(hi));
    }
    if (u == -inf && std::isfinite(lo))
    {
      EXPECT_LT(steps.up(u), steps.up(lo));
    }
  }
  EXPECT_GT(kept, 20000);
  // NaN takes the step that keeps a voxel; the infinite ends keep steps of their own, so that
  // a bound of +inf (-inf) still fails against every finite band's top (bottom).
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(steps.down(-3.0), 0);
  EXPECT_EQ(steps.down(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(steps.up(std::numeric_limits<double>::quiet_NaN()), RangeSteps::kLast);
  EXPECT_EQ(steps.down(inf), RangeSteps::kLast);
  EXPECT_EQ(steps.down(1e9), RangeSteps::kLast - 1);
  EXPECT_EQ(steps.up(-inf), 0);
  EXPECT_EQ(steps.up(-3.0), 1);
  EXPECT_EQ(steps.up(inf), RangeSteps::kLast);
  EXPECT_LE(steps.unit, 35.0 / 65000.0 + 1e-12);
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
