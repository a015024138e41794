/**
 * @file text_parsing.h
 * @brief Strict number parsing for command-line tools and text files: the whole text must be
 *        the number (surrounding blanks allowed), and errors name what was being parsed.
 */
#pragma once

#include <string>
#include <utility>

namespace fdml_localization
{
namespace core
{
/// @p text without leading and trailing white space (space, tab, CR, LF, FF, VT).
std::string trim(const std::string& text);

/**
 * @brief Parses @p text as a number.
 * @param what names the value in the error (a flag, or "FILE:LINE: field")
 * @param allow_infinite accept "inf" / "-inf" (NaN is never accepted)
 * @throws std::invalid_argument "WHAT: 'TEXT' is not a (finite) number"
 */
double parseNumber(const std::string& text, const std::string& what, bool allow_infinite = false);

/// Parses @p text as an integer in [-1e9, 1e9]. @throws std::invalid_argument naming @p what.
int parseInteger(const std::string& text, const std::string& what);

/// Parses "X,Y" (two finite numbers) into @p x and @p y. @throws std::invalid_argument naming @p what.
void parsePoint(const std::string& text, const std::string& what, double& x, double& y);

/**
 * @brief Splits "BASE[:SCALE]" (a map file or a generated map, and a scale about the origin) on
 *        its last ':'; without one the scale is 1.
 * @throws std::invalid_argument naming @p what when SCALE is not a number in (0, 1e6]
 */
std::pair<std::string, double> splitScale(const std::string& text, const std::string& what);

}  // namespace core
}  // namespace fdml_localization
