/**
 * @file readings_csv.h
 * @brief fdml_localize's readings file: a CSV with the header "gx,gy,gtheta,d", optionally
 *        ",max_range" [m], then optionally ",fov" (the sensor's full field of view [deg], 0 = a
 *        ray); one reading per line [m, rad]; d may be "inf" (no return within max_range).
 *        Every error names the file and line.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"

#include <stdexcept>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace tools
{
namespace core = fdml_localization::core;

/// Bad input, its message naming the file and line (the tools exit 2).
struct InputError : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// The readings of a CSV file, each with the line it came from.
struct CsvReadings
{
  std::vector<core::Reading> readings;
  std::vector<int> lines;
};

/**
 * @brief Reads @p path (a regular text file); readings without a max_range column get
 *        @p default_max_range [m].
 * @throws InputError naming the file and line
 */
CsvReadings readReadingsCsv(const std::string& path, double default_max_range);

/// The core's check of the batch (core::validateReadings), its "reading N: ..." errors turned into
/// "FILE:LINE: ...". @throws InputError
void validateCsvReadings(const CsvReadings& csv, const std::string& path, const core::LocalizerOptions& options);

}  // namespace tools
}  // namespace fdml_localization
