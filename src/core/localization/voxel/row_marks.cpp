// The preimage tests of one row of voxels: scalar, SSE2 (any x86-64) and AVX2 (chosen at run
// time: the build targets any x86-64).
#include "fdml_localization/core/localization/voxel/row_marks.h"

#ifdef __SSE2__
#include <emmintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define FDML_AVX2_ROWS 1
#endif

#include <limits>

namespace fdml_localization
{
namespace core
{
namespace
{
#ifdef FDML_AVX2_ROWS
/// Whether the CPU has AVX2 (the CPU model is read first: this runs among static initialisers).
bool haveAvx2()
{
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2");
}

const bool kHaveAvx2 = haveAvx2();

/// The float test eight voxels per step from @p ix (a multiple of 8) on; returns where it stopped.
__attribute__((target("avx2"))) int markRowAvx2(const float* rmin, const float* rmax, std::ptrdiff_t shift, int ix,
                                                int end, float lo, float hi, std::uint64_t* row)
{
  const __m256 vlo = _mm256_set1_ps(lo);
  const __m256 vhi = _mm256_set1_ps(hi);
  for (; ix + 8 <= end; ix += 8)
  {
    const __m256 below = _mm256_cmp_ps(_mm256_loadu_ps(rmin + (ix + shift)), vhi, _CMP_LE_OQ);
    const __m256 above = _mm256_cmp_ps(_mm256_loadu_ps(rmax + (ix + shift)), vlo, _CMP_GE_OQ);
    row[ix >> 6] |= static_cast<std::uint64_t>(_mm256_movemask_ps(_mm256_and_ps(below, above))) << (ix & 63);
  }
  return ix;
}

/// The step test sixteen voxels per step from @p ix (a multiple of 16) on: a <= b (unsigned)
/// where max(a, b) == b; the lanes' masks packed to bytes give one bit per voxel.
__attribute__((target("avx2"))) int markRowAvx2(const std::uint16_t* rmin, const std::uint16_t* rmax,
                                                std::ptrdiff_t shift, int ix, int end, std::uint16_t lo,
                                                std::uint16_t hi, std::uint64_t* row)
{
  const __m256i vlo = _mm256_set1_epi16(static_cast<short>(lo));
  const __m256i vhi = _mm256_set1_epi16(static_cast<short>(hi));
  for (; ix + 16 <= end; ix += 16)
  {
    const __m256i a = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rmin + (ix + shift)));
    const __m256i b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rmax + (ix + shift)));
    const __m256i below = _mm256_cmpeq_epi16(_mm256_max_epu16(a, vhi), vhi);
    const __m256i above = _mm256_cmpeq_epi16(_mm256_max_epu16(b, vlo), b);
    const __m256i in = _mm256_and_si256(below, above);
    const __m128i bytes = _mm_packs_epi16(_mm256_castsi256_si128(in), _mm256_extracti128_si256(in, 1));
    row[ix >> 6] |= static_cast<std::uint64_t>(static_cast<unsigned>(_mm_movemask_epi8(bytes))) << (ix & 63);
  }
  return ix;
}
#endif

#ifdef __SSE2__
/// The float test four voxels per step from @p ix (a multiple of 4) on.
int markRowSse2(const float* rmin, const float* rmax, std::ptrdiff_t shift, int ix, int end, float lo, float hi,
                std::uint64_t* row)
{
  const __m128 vlo = _mm_set1_ps(lo);
  const __m128 vhi = _mm_set1_ps(hi);
  for (; ix + 4 <= end; ix += 4)
  {
    const __m128 below = _mm_cmple_ps(_mm_loadu_ps(rmin + (ix + shift)), vhi);
    const __m128 in = _mm_and_ps(below, _mm_cmpge_ps(_mm_loadu_ps(rmax + (ix + shift)), vlo));
    row[ix >> 6] |= static_cast<std::uint64_t>(_mm_movemask_ps(in)) << (ix & 63);
  }
  return ix;
}

/// The step test eight voxels per step from @p ix (a multiple of 8) on: unsigned order as the
/// signed order of the values with their top bit flipped.
int markRowSse2(const std::uint16_t* rmin, const std::uint16_t* rmax, std::ptrdiff_t shift, int ix, int end,
                std::uint16_t lo, std::uint16_t hi, std::uint64_t* row)
{
  const __m128i flip = _mm_set1_epi16(static_cast<short>(0x8000));
  const __m128i vlo = _mm_xor_si128(_mm_set1_epi16(static_cast<short>(lo)), flip);
  const __m128i vhi = _mm_xor_si128(_mm_set1_epi16(static_cast<short>(hi)), flip);
  for (; ix + 8 <= end; ix += 8)
  {
    const __m128i a = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(rmin + (ix + shift))), flip);
    const __m128i b = _mm_xor_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(rmax + (ix + shift))), flip);
    // Out when a > hi or lo > b.
    const __m128i out = _mm_or_si128(_mm_cmpgt_epi16(a, vhi), _mm_cmpgt_epi16(vlo, b));
    const __m128i bytes = _mm_packs_epi16(out, out);
    const unsigned in = ~static_cast<unsigned>(_mm_movemask_epi8(bytes)) & 0xffu;
    row[ix >> 6] |= static_cast<std::uint64_t>(in) << (ix & 63);
  }
  return ix;
}
#endif

/// Runs the scalar test up to an aligned index, the vector kernels (AVX2 when present, then
/// SSE2; each aligned group lies inside one 64-bit word), and the scalar test on the rest.
/// @p top: the band's top for the vector kernels (the largest value for a no-return reading,
/// which tests only the upper bounds).
template <class T>
void markRowWith(const T* rmin, const T* rmax, std::ptrdiff_t shift, int begin, int end, T lo, T hi, T top,
                 bool no_return, std::uint64_t* row)
{
  auto scalar = [&](int ix) {
    const T a = rmin[ix + shift];
    const T b = rmax[ix + shift];
    const bool in = no_return ? b >= lo : (a <= hi && b >= lo);
    row[ix >> 6] |= static_cast<std::uint64_t>(in) << (ix & 63);
  };
  constexpr int kWide = sizeof(T) == 2 ? 16 : 8;
  constexpr int kNarrow = sizeof(T) == 2 ? 8 : 4;
  int ix = begin;
#ifdef FDML_AVX2_ROWS
  if (kHaveAvx2)
  {
    for (; ix < end && ix % kWide != 0; ++ix)
    {
      scalar(ix);
    }
    ix = markRowAvx2(rmin, rmax, shift, ix, end, lo, top, row);
  }
#endif
#ifdef __SSE2__
  for (; ix < end && ix % kNarrow != 0; ++ix)
  {
    scalar(ix);
  }
  ix = markRowSse2(rmin, rmax, shift, ix, end, lo, top, row);
#endif
  for (; ix < end; ++ix)
  {
    scalar(ix);
  }
}
}  // namespace

void markRow(const float* rmin, const float* rmax, std::ptrdiff_t shift, int begin, int end, float lo, float hi,
             bool no_return, std::uint64_t* row)
{
  const float top = no_return ? std::numeric_limits<float>::infinity() : hi;
  markRowWith(rmin, rmax, shift, begin, end, lo, hi, top, no_return, row);
}

void markRow(const std::uint16_t* rmin, const std::uint16_t* rmax, std::ptrdiff_t shift, int begin, int end,
             std::uint16_t lo, std::uint16_t hi, bool no_return, std::uint64_t* row)
{
  const std::uint16_t top = no_return ? std::numeric_limits<std::uint16_t>::max() : hi;
  markRowWith(rmin, rmax, shift, begin, end, lo, hi, top, no_return, row);
}

}  // namespace core
}  // namespace fdml_localization
