/**
 * @file grid_tolerances.h
 * @brief The one tolerance policy for maps that come from an occupancy grid (a map_server
 *        YAML, a map topic, or a `.poly` converted from a grid), and the `.poly` comment header
 *        that records the grid's cell size.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"

#include <iosfwd>
#include <string>

namespace fdml_localization
{
namespace core
{
/// Which localizer tolerances the user set explicitly (those are never changed).
struct ExplicitTolerances
{
  bool range_tolerance = false;
  bool agreement_tolerance = false;
};

/**
 * @brief The options to use with a map converted from a grid of cells of @p cell_size [m]:
 *        its walls are good to about a cell (cell quantisation and simplification), so a
 *        range_tolerance not set explicitly becomes max(its value, cell_size) and an
 *        agreement_tolerance not set explicitly max(its value, 2 * cell_size).
 *        @p cell_size <= 0 or not finite (a map not from a grid) changes nothing.
 */
LocalizerOptions withGridTolerances(const LocalizerOptions& options, double cell_size,
                                    const ExplicitTolerances& set = {});

/// The `.poly` comment line (without the "# ") recording a source grid's cell size [m]:
/// "fdml: cell_size 0.05".
std::string cellSizeHeader(double cell_size);

/**
 * @brief The cell size [m] recorded by a cellSizeHeader() line among the comment lines at the
 *        head of a `.poly` stream (before its first vertex); 0 when there is none.
 * @throws MapError naming @p source and the line when the header's value is not a number > 0.
 */
double readCellSizeHeader(std::istream& in, const std::string& source);

/// readCellSizeHeader() of the file @p path (0 when it cannot be opened: the loader reports that).
double readPolyCellSize(const std::string& path);

}  // namespace core
}  // namespace fdml_localization
