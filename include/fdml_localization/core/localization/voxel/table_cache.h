/**
 * @file table_cache.h
 * @brief On-disk cache of distance tables: a versioned binary file keyed by the map's hash
 *        and the grid, with a checksum over the whole file. A missing, truncated, corrupt or
 *        mismatching file is never trusted: the table is rebuilt and the file rewritten
 *        atomically (temporary file, then rename).
 */
#pragma once

#include "fdml_localization/core/localization/voxel/distance_table.h"

#include <cstdint>
#include <string>

namespace fdml_localization
{
namespace core
{
/// Format version written into every cache file; bumped on any layout change.
constexpr std::uint32_t kTableCacheVersion = 1;

/// Where the table of (map, grid) lives inside @p dir.
std::string tableCachePath(const std::string& dir, std::uint64_t map_hash, const GridSpec& spec);

/**
 * @brief Writes the table atomically (a temporary file in the same folder, then rename),
 *        creating @p path's folder when needed.
 * @return false (with the reason in @p error when not null) when the file cannot be written
 */
bool saveTable(const std::string& path, std::uint64_t map_hash, const DistanceTable& table,
               std::string* error = nullptr);

/**
 * @brief Loads a table written by saveTable() for exactly this map hash and grid.
 * @return false (with the reason in @p error when not null) for a missing, truncated,
 *         corrupt (checksum), foreign-version or mismatching file
 */
bool loadTable(const std::string& path, std::uint64_t map_hash, const GridSpec& spec, DistanceTable& table,
               std::string* error = nullptr);

/// How loadOrBuildTable() obtained its table.
enum class TableSource
{
  Built,          ///< built, no cache folder given
  Loaded,         ///< loaded from a valid cache file
  BuiltAndSaved,  ///< no cache file yet: built and saved
  Rebuilt         ///< the cache file was unusable (corrupt, truncated, ...): rebuilt and rewritten
};

/**
 * @brief The table of (map, grid): from the cache in @p cache_dir when valid, else built
 *        (and saved there when @p cache_dir is not empty). A cache problem never stops the
 *        build: a corrupt, truncated or stale file is rebuilt and rewritten; a path that is not
 *        a regular file (a directory, a FIFO, a symbolic-link loop, a name too long) is never
 *        opened and never replaced; a file that cannot be saved is skipped.
 * @param reason when not null, receives the warning to show once (naming the cache path and
 *        the reason: a file rejected, not used or not saved); empty when the cache just worked
 */
DistanceTable loadOrBuildTable(const MapRayCaster& map, const GridSpec& spec, const std::string& cache_dir, int threads,
                               TableSource* source = nullptr, std::string* reason = nullptr);

class Localizer;

/// The cache warning of @p localizer's voxel engine (see loadOrBuildTable()), empty when
/// there is none or the engine keeps no cache. Tools and the node show it once.
std::string tableCacheWarning(Localizer& localizer);

/// 64-bit checksum of a byte range (word-wise multiply-xorshift; not cryptographic).
std::uint64_t checksum64(const void* data, std::size_t bytes, std::uint64_t seed = 0);

}  // namespace core
}  // namespace fdml_localization
