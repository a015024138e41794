#include "fdml_localization/core/localization/voxel/table_cache.h"

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/voxel/voxel_engine.h"
#include "fdml_localization/core/util/file_checks.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>

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
      const std::string why = std::strerror(errno);
      std::filesystem::remove(tmp, ec);
      setError(error, "cannot write " + tmp + ": " + why);
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

namespace
{
/// Reads at most @p limit bytes of a regular file opened non-blocking (a FIFO, a device or a
/// directory is refused before it is opened). Returns false with the reason in @p error.
bool readRegularFile(const std::string& path, std::size_t limit, std::vector<char>& bytes, std::string& error)
{
  const std::string problem = regularFileProblem(path);
  if (!problem.empty())
  {
    error = path + ": " + problem;
    return false;
  }
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  struct stat st;
  if (fd < 0 || ::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode))
  {
    error = path + ": cannot open: " + (fd < 0 ? std::strerror(errno) : "not a regular file");
    if (fd >= 0)
    {
      ::close(fd);
    }
    return false;
  }
  bytes.resize(limit);
  std::size_t got = 0;
  while (got < limit)
  {
    const ssize_t n = ::read(fd, bytes.data() + got, limit - got);
    if (n < 0 && errno == EINTR)
    {
      continue;
    }
    if (n <= 0)
    {
      break;
    }
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  bytes.resize(got);
  return true;
}
}  // namespace

bool loadTable(const std::string& path, std::uint64_t map_hash, const GridSpec& spec, DistanceTable& table,
               std::string* error)
{
  const Header expected = makeHeader(map_hash, spec);
  const std::size_t value_bytes = spec.voxelCount() * sizeof(float);
  const std::size_t file_bytes = sizeof(Header) + value_bytes + sizeof(std::uint64_t);
  std::vector<char> bytes;
  std::string why;
  if (!readRegularFile(path, file_bytes + 1, bytes, why))
  {
    setError(error, why);
    return false;
  }
  Header header;
  if (bytes.size() < sizeof(header))
  {
    setError(error, path + ": truncated header");
    return false;
  }
  std::memcpy(&header, bytes.data(), sizeof(header));
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
  if (bytes.size() < file_bytes)
  {
    setError(error, path + ": truncated data");
    return false;
  }
  if (bytes.size() > file_bytes)
  {
    setError(error, path + ": trailing bytes after the checksum");
    return false;
  }
  std::vector<float> values(spec.voxelCount());
  std::uint64_t stored = 0;
  std::memcpy(values.data(), bytes.data() + sizeof(header), value_bytes);
  std::memcpy(&stored, bytes.data() + sizeof(header) + value_bytes, sizeof(stored));
  std::uint64_t sum = checksum64(&header, sizeof(header));
  sum = checksum64(values.data(), value_bytes, sum);
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
  TableSource unused;
  source = source ? source : &unused;
  *source = TableSource::Built;
  if (cache_dir.empty())
  {
    return DistanceTable::build(map, spec, threads);
  }
  const std::uint64_t map_hash = map.map().hash();
  const std::string path = tableCachePath(cache_dir, map_hash, spec);
  const std::string problem = regularFileProblem(path);
  DistanceTable table;
  std::string why;
  if (problem.empty() && loadTable(path, map_hash, spec, table, &why))
  {
    *source = TableSource::Loaded;
    return table;
  }
  table = DistanceTable::build(map, spec, threads);
  if (problem == "no such file")
  {
    *source = TableSource::BuiltAndSaved;
  }
  else if (problem.empty())
  {
    *source = TableSource::Rebuilt;  // a regular file, rejected: rewritten below
    why = "cache file rejected (" + why + "); tables rebuilt";
  }
  else
  {
    setError(reason, "cache file " + path + " not used: " + problem + "; tables built without the cache");
    return table;
  }
  std::string save_error;
  if (!saveTable(path, map_hash, table, &save_error))
  {
    *source = TableSource::Built;
    why += std::string(why.empty() ? "" : "; ") + "cache not saved: " + save_error;
  }
  setError(reason, why);
  return table;
}

std::string tableCacheWarning(Localizer& localizer)
{
  const auto* voxel = dynamic_cast<const VoxelEngine*>(&localizer.engine());
  return voxel ? voxel->cacheMessage() : std::string();
}

}  // namespace core
}  // namespace fdml_localization
