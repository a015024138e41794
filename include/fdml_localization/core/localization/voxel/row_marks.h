/**
 * @file row_marks.h
 * @brief The preimage tests of one row of voxels (voxel_preimage.cpp): a voxel is marked when
 *        the interval of range bounds it reads meets a reading's band. Float bounds (the
 *        seeding's sample table) and 16-bit range steps (RangeSteps: the conservative windows),
 *        four, eight or sixteen voxels per step where the CPU allows (AVX2 chosen at run time).
 */
#pragma once

#include <cstddef>
#include <cstdint>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Sets bit ix of @p row for ix in [begin, end) when [rmin[ix + shift], rmax[ix + shift]]
 *        meets [lo, hi] (no_return: when rmax[ix + shift] >= lo); ix + shift >= 0 on that range.
 *        Bounds and band in metres.
 */
void markRow(const float* rmin, const float* rmax, std::ptrdiff_t shift, int begin, int end, float lo, float hi,
             bool no_return, std::uint64_t* row);

/// markRow() over bounds and a band in range steps (RangeSteps).
void markRow(const std::uint16_t* rmin, const std::uint16_t* rmax, std::ptrdiff_t shift, int begin, int end,
             std::uint16_t lo, std::uint16_t hi, bool no_return, std::uint64_t* row);

}  // namespace core
}  // namespace fdml_localization
