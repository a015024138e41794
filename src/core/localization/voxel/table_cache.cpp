#include "fdml_localization/core/localization/voxel/table_cache.h"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
constexpr char kMagic[8] = { 'F', 'D', 'M', 'L', 'T', 'B', 'L', '\0' };

/// Fixed-size file header (followed by the floats and an 8-byte checksum).
struct Header
{
  char magic[8];
  std::uint32_t version;
  std::uint32_t float_bytes;
  std::uint64_t map_hash;
  double origin_x;
  double origin_y;
  double cell;
  std::int32_t nx;
  std::int32_t ny;
  std::int32_t nt;
  std::int32_t reserved;
  std::uint64_t value_count;
};

void setError(std::string* error, const std::string& text)
{
  if (error)
  {
    *error = text;
  }
}

std::uint64_t mix(std::uint64_t h)
{
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdULL;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ULL;
  h ^= h >> 33;
  return h;
}

Header makeHeader(std::uint64_t map_hash, const GridSpec& spec)
{
  Header header;
  std::memset(&header, 0, sizeof(header));
  std::memcpy(header.magic, kMagic, sizeof(kMagic));
  header.version = kTableCacheVersion;
  header.float_bytes = sizeof(float);
  header.map_hash = map_hash;
  header.origin_x = spec.origin_x;
  header.origin_y = spec.origin_y;
  header.cell = spec.cell;
  header.nx = spec.nx;
  header.ny = spec.ny;
  header.nt = spec.nt;
  header.value_count = spec.voxelCount();
  return header;
}
}  // namespace

std::uint64_t checksum64(const void* data, std::size_t bytes, std::uint64_t seed)
{
  const auto* p = static_cast<const unsigned char*>(data);
  std::uint64_t h = mix(seed ^ 0x27d4eb2f165667c5ULL ^ bytes);
  std::size_t k = 0;
  for (; k + 8 <= bytes; k += 8)
  {
    std::uint64_t w = 0;
    std::memcpy(&w, p + k, 8);
    h = (h ^ mix(w + k)) * 0x9e3779b97f4a7c15ULL;
    h ^= h >> 29;
  }
  std::uint64_t tail = 0;
  std::memcpy(&tail, p + k, bytes - k);
  return mix(h ^ mix(tail + bytes));
}

std::string tableCachePath(const std::string& dir, std::uint64_t map_hash, const GridSpec& spec)
{
  char name[96];
  std::snprintf(name, sizeof(name), "fdml_table_v%u_%016llx_%016llx.bin", static_cast<unsigned>(kTableCacheVersion),
                static_cast<unsigned long long>(map_hash), static_cast<unsigned long long>(spec.hash()));
  return (std::filesystem::path(dir) / name).string();
}

bool saveTable(const std::string& path, std::uint64_t map_hash, const DistanceTable& table, std::string* error)
{
  static std::atomic<unsigned> counter{ 0 };
  const Header header = makeHeader(map_hash, table.spec());
  const std::vector<float>& values = table.values();
  std::uint64_t sum = checksum64(&header, sizeof(header));
  sum = checksum64(values.data(), values.size() * sizeof(float), sum);

  std::error_code ec;
  const std::filesystem::path target(path);
  if (target.has_parent_path())
  {
    std::filesystem::create_directories(target.parent_path(), ec);
    if (ec)
    {
      setError(error, "cannot create folder " + target.parent_path().string() + ": " + ec.message());
      return false;
    }
  }
  std::ostringstream tmp_name;
  tmp_name << path << ".tmp." << ::getpid() << "." << counter++;
  const std::string tmp = tmp_name.str();
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(&header), sizeof(header));
    out.write(reinterpret_cast<const char*>(values.data()),
              static_cast<std::streamsize>(values.size() * sizeof(float)));
    out.write(reinterpret_cast<const char*>(&sum), sizeof(sum));
    out.close();
    if (!out)
    {
      std::filesystem::remove(tmp, ec);
      setError(error, "cannot write " + tmp);
      return false;
    }
  }
  std::filesystem::rename(tmp, target, ec);
  if (ec)
  {
    std::filesystem::remove(tmp, ec);
    setError(error, "cannot rename " + tmp + " to " + path + ": " + ec.message());
    return false;
  }
  return true;
}

bool loadTable(const std::string& path, std::uint64_t map_hash, const GridSpec& spec, DistanceTable& table,
               std::string* error)
{
  std::ifstream in(path, std::ios::binary);
  if (!in)
  {
    setError(error, path + ": cannot open");
    return false;
  }
  const Header expected = makeHeader(map_hash, spec);
  Header header;
  if (!in.read(reinterpret_cast<char*>(&header), sizeof(header)))
  {
    setError(error, path + ": truncated header");
    return false;
  }
  if (std::memcmp(header.magic, kMagic, sizeof(kMagic)) != 0)
  {
    setError(error, path + ": not a distance-table file");
    return false;
  }
  if (header.version != kTableCacheVersion)
  {
    setError(error,
             path + ": version " + std::to_string(header.version) + ", expected " + std::to_string(kTableCacheVersion));
    return false;
  }
  if (std::memcmp(&header, &expected, sizeof(header)) != 0)
  {
    setError(error, path + ": written for another map or grid");
    return false;
  }
  std::vector<float> values(spec.voxelCount());
  std::uint64_t stored = 0;
  if (!in.read(reinterpret_cast<char*>(values.data()), static_cast<std::streamsize>(values.size() * sizeof(float))) ||
      !in.read(reinterpret_cast<char*>(&stored), sizeof(stored)))
  {
    setError(error, path + ": truncated data");
    return false;
  }
  if (in.peek() != std::ifstream::traits_type::eof())
  {
    setError(error, path + ": trailing bytes after the checksum");
    return false;
  }
  std::uint64_t sum = checksum64(&header, sizeof(header));
  sum = checksum64(values.data(), values.size() * sizeof(float), sum);
  if (sum != stored)
  {
    setError(error, path + ": checksum mismatch (corrupt file)");
    return false;
  }
  table = DistanceTable(spec, std::move(values));
  return true;
}

DistanceTable loadOrBuildTable(const MapRayCaster& map, const GridSpec& spec, const std::string& cache_dir, int threads,
                               TableSource* source, std::string* reason)
{
  setError(reason, "");
  if (cache_dir.empty())
  {
    if (source)
    {
      *source = TableSource::Built;
    }
    return DistanceTable::build(map, spec, threads);
  }
  const std::uint64_t map_hash = map.map().hash();
  const std::string path = tableCachePath(cache_dir, map_hash, spec);
  const bool existed = std::filesystem::exists(path);
  DistanceTable table;
  std::string why;
  if (existed && loadTable(path, map_hash, spec, table, &why))
  {
    if (source)
    {
      *source = TableSource::Loaded;
    }
    return table;
  }
  setError(reason, why);
  table = DistanceTable::build(map, spec, threads);
  std::string save_error;
  saveTable(path, map_hash, table, &save_error);
  if (source)
  {
    *source = existed ? TableSource::Rebuilt : TableSource::BuiltAndSaved;
  }
  if (!save_error.empty() && reason)
  {
    *reason += (reason->empty() ? "" : "; ") + save_error;
  }
  return table;
}

}  // namespace core
}  // namespace fdml_localization
