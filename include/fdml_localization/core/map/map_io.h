/**
 * @file map_io.h
 * @brief Reading and writing `.poly` map files.
 *
 * Format: one "x y" vertex per line [m]; a blank line starts a new ring; the first ring
 * is the outer boundary and every later ring is a hole; '#' starts a comment that runs to
 * the end of the line. Compatible with the one-ring files of the paper's public code.
 */
#pragma once

#include "fdml_localization/core/map/polygon_map.h"

#include <iosfwd>
#include <string>

namespace fdml_localization
{
namespace core
{
/// Loads and validates a `.poly` file. @throws MapError naming the file, the line and the reason.
PolygonMap loadPolyFile(const std::string& path);

/// Parses `.poly` text; @p source names it in errors. @throws MapError.
PolygonMap parsePoly(std::istream& in, const std::string& source);

/// Writes a map in `.poly` format (17 significant digits, so a round trip is exact).
void writePoly(std::ostream& out, const PolygonMap& map, const std::string& comment = "");

/// Saves a map to a file. @throws std::runtime_error when the file cannot be written.
void savePolyFile(const std::string& path, const PolygonMap& map, const std::string& comment = "");

}  // namespace core
}  // namespace fdml_localization
