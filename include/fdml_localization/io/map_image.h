/**
 * @file map_image.h
 * @brief The image of a map_server map, checked before it is decoded: a regular file (never a
 *        FIFO or a device, which could block), a size read from its header within the limits
 *        below, and for binary PGM/PPM every pixel byte present (stb_image would otherwise fill
 *        a truncated file's missing pixels with whatever memory held).
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace io
{
/// Largest map image accepted [cells]: 100 M cells (10,000 x 10,000; 500 m x 500 m at 5 cm).
/// Decoding and converting it takes about a gigabyte of memory.
constexpr long long kMaxGridCells = 100000000LL;
/// Largest image side accepted [cells].
constexpr int kMaxGridSide = 100000;

/// Size of a map image, from its header.
struct ImageInfo
{
  int width = 0;     ///< [pixels]
  int height = 0;    ///< [pixels]
  int channels = 0;  ///< 1 grey, 2 grey + alpha, 3 RGB, 4 RGBA
};

/**
 * @brief Reads an image's size from its header without decoding it and checks it: a regular
 *        file, a format stb_image reads, 1 <= width, height <= kMaxGridSide, width * height <=
 *        kMaxGridCells, and for a binary PGM/PPM the whole pixel data present.
 * @param named_by the file naming the image (a map YAML), cited in errors; may be empty
 * @throws core::MapError naming the image and the problem
 */
ImageInfo readImageInfo(const std::string& path, const std::string& named_by = "");

/**
 * @brief readImageInfo(), then decodes the image to 8-bit samples (channels interleaved, the
 *        top row first). @throws core::MapError naming the image and the problem.
 */
std::vector<std::uint8_t> loadImagePixels(const std::string& path, ImageInfo& info, const std::string& named_by = "");

}  // namespace io
}  // namespace fdml_localization
