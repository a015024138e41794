/**
 * @file file_checks.h
 * @brief Checks made before a file is opened, so that a FIFO, a device or a directory given as
 *        a map, readings or cache file is reported instead of blocking or being misread.
 */
#pragma once

#include <string>

namespace fdml_localization
{
namespace core
{
/**
 * @brief Why @p path cannot be read as a regular file, or "" when it can. Follows symbolic
 *        links; never opens the file (so never blocks). Examples: "no such file" (the one
 *        answer meaning nothing is there), "a dangling symbolic link (...)",
 *        "not a regular file (a directory)", "not a regular file (a FIFO)",
 *        "cannot access it: Too many levels of symbolic links".
 */
std::string regularFileProblem(const std::string& path);

}  // namespace core
}  // namespace fdml_localization
