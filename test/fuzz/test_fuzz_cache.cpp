// Fuzz, in process: the distance-table cache file corrupted (truncated, bit-flipped, bytes
// appended, emptied) or replaced by a directory, a FIFO, a device, a symbolic-link loop or a
// dangling link, and cache folders that are files or have over-long names. Every case must
// give the right table (equal to one built without a cache), with one warning naming the
// path and the reason, and never open a non-regular file.
#include "fdml_localization/core/localization/voxel/table_cache.h"
#include "fuzz_mutator.h"
#include "localizer_test_utils.h"

#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <iostream>

namespace fdml_localization
{
namespace fuzz
{
namespace
{
namespace fs = std::filesystem;

/// What replaces the cache file (or folder) in a case.
enum class Damage
{
  Bytes,      ///< the file's bytes mutated
  Directory,  ///< a directory at the file's path
  Fifo,       ///< a FIFO at the file's path
  Device,     ///< a link to /dev/zero
  LinkLoop,   ///< two links pointing at each other
  Dangling,   ///< a link to nothing
  FolderIsFile,
  LongName,  ///< a cache folder name longer than PATH_MAX
  Count
};

/// Puts the damage in place; returns the cache folder to use.
std::string damage(Damage kind, const std::string& dir, const std::string& path, const std::string& valid,
                   Mutator& mutator, std::string& what)
{
  std::error_code ec;
  fs::remove_all(dir, ec);
  fs::create_directories(dir);
  switch (kind)
  {
    case Damage::Bytes:
      writeFile(path, mutator.mutateBytes(valid, what));
      break;
    case Damage::Directory:
      fs::create_directories(path);
      break;
    case Damage::Fifo:
      ::mkfifo(path.c_str(), 0600);
      break;
    case Damage::Device:
      fs::create_symlink("/dev/zero", path);
      break;
    case Damage::LinkLoop:
      fs::create_symlink(path + ".other", path);
      fs::create_symlink(path, path + ".other");
      break;
    case Damage::Dangling:
      fs::create_symlink(dir + "/nowhere/at/all", path);
      break;
    case Damage::FolderIsFile:
      writeFile(dir + "/plain_file", "not a folder");
      return dir + "/plain_file";
    default:
      return dir + "/" + std::string(5000, 'x');
  }
  return dir;
}
}  // namespace

TEST(FuzzCache, DamagedCachesNeverStopALocalization)
{
  Tally tally{ "cache" };
  Mutator mutator(1503);
  const auto map = core::test::lRoomMap();
  const core::GridSpec spec = core::GridSpec::fromMap(map->map(), 16, 0);
  const core::DistanceTable reference = core::DistanceTable::build(*map, spec, 1);
  const std::string dir = (fs::temp_directory_path() / ("fdml_fuzz_cache_" + std::to_string(::getpid()))).string();
  fs::create_directories(dir);
  const std::string valid_path = dir + "/valid.bin";
  ASSERT_TRUE(core::saveTable(valid_path, map->map().hash(), reference));
  const std::string valid = readFile(valid_path);
  const int cases = caseCount(0.03, 300);
  for (int c = 0; c < cases; ++c)
  {
    const auto kind = static_cast<Damage>(c % static_cast<int>(Damage::Count));
    std::string what = "cache case " + std::to_string(c) + " kind " + std::to_string(static_cast<int>(kind)) + ":";
    const std::string path = core::tableCachePath(dir, map->map().hash(), spec);
    const std::string cache_dir = damage(kind, dir, path, valid, mutator, what);
    const bool unchanged = kind == Damage::Bytes && readFile(path) == valid;
    ++tally.cases;
    try
    {
      core::TableSource source;
      std::string warning;
      const core::DistanceTable table = core::loadOrBuildTable(*map, spec, cache_dir, 1, &source, &warning);
      // Bit for bit (the table holds NaN outside the map, which == would call different).
      if (table.values().size() != reference.values().size() ||
          std::memcmp(table.values().data(), reference.values().data(), table.values().size() * sizeof(float)) != 0)
      {
        tally.fail(what + ": wrong table");
      }
      const std::string named = kind == Damage::FolderIsFile || kind == Damage::LongName ? cache_dir : path;
      if (!unchanged && (warning.empty() || warning.find(named) == std::string::npos))
      {
        tally.fail(what + ": no warning naming " + named.substr(0, 80) + ": '" + warning.substr(0, 200) + "'");
      }
      (warning.empty() ? tally.accepted : tally.rejected)++;
    }
    catch (const std::exception& e)
    {
      tally.fail(what + ": " + typeid(e).name() + ": " + e.what());
    }
  }
  fs::remove_all(dir);
  std::cout << tally.report() << std::endl;
  EXPECT_TRUE(tally.failures.empty()) << ::testing::PrintToString(tally.failures);
}

}  // namespace fuzz
}  // namespace fdml_localization
