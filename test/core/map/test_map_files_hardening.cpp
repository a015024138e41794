// Hostile map files (issue 15): NUL bytes, huge coordinates, truncated or huge images, FIFOs
// and directories where a file is expected. Each ends in a MapError naming the file (and the
// line where there is one), quickly, never in a crash, a hang or uninitialised pixels.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/io/map_files.h"
#include "fdml_localization/io/map_image.h"

#include "temp_dir_test.h"

#include <gtest/gtest.h>
#include <stb/stb_image_write.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

namespace fdml_localization
{
namespace
{
namespace fs = std::filesystem;
using core::MapError;

class MapFilesHardening : public fdml_localization::test::TempDirTest
{
protected:
  /// A map_server YAML naming @p image.
  std::string yaml(const std::string& image) const
  {
    return write("map.yaml", "image: " + image +
                                 "\nresolution: 0.05\norigin: [0, 0, 0]\nnegate: 0\n"
                                 "occupied_thresh: 0.65\nfree_thresh: 0.196\n");
  }
  /// A valid 40 x 30 grid saved as map.yaml + map.pgm.
  std::string gridYaml() const
  {
    core::OccupancyGrid grid;
    grid.width = 40;
    grid.height = 30;
    grid.cells.assign(40 * 30, 0);
    for (int i = 0; i < 40; ++i)
    {
      grid.cells[i] = grid.cells[29 * 40 + i] = 100;
    }
    io::saveOccupancyGridYaml(file("map.yaml"), grid);
    return file("map.yaml");
  }
};

/// Expects a MapError from @p load whose file is @p path, whose line is @p line (-1: any) and
/// whose message contains @p words.
template <class Load>
void expectMapError(Load load, const std::string& path, int line, const std::string& words)
{
  try
  {
    load();
    ADD_FAILURE() << path << ": no error";
  }
  catch (const MapError& e)
  {
    EXPECT_EQ(e.file(), path) << e.what();
    if (line >= 0)
    {
      EXPECT_EQ(e.line(), line) << e.what();
    }
    EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
  }
}
}  // namespace

TEST_F(MapFilesHardening, NulByteInAPolyLineNamesFileAndLine)
{
  const std::string path = write("nul.poly", std::string("0 0\n4 0\n4 4\0 junk\n0 4\n", 23));
  expectMapError([&] { core::loadPolyFile(path); }, path, 3, "NUL byte");
}

TEST_F(MapFilesHardening, HugeCoordinatesNameFileAndLine)
{
  for (const std::string huge : { "1e19", "-3e300", "1.5e9" })
  {
    const std::string path = write("huge.poly", "0 0\n4 0\n" + huge + " 4\n0 4\n");
    expectMapError([&] { core::loadPolyFile(path); }, path, 3, "beyond");
  }
  const std::string path = write("big_ok.poly", "0 0\n4e8 0\n4e8 4e8\n0 4e8\n");
  EXPECT_NO_THROW(core::loadPolyFile(path));
}

TEST_F(MapFilesHardening, FifoOrDirectoryAsMapIsAnErrorNotAHang)
{
  const std::string fifo = file("fifo.poly");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  expectMapError([&] { core::loadPolyFile(fifo); }, fifo, 0, "FIFO");
  expectMapError([&] { io::loadMapFile(fifo); }, fifo, 0, "FIFO");
  const std::string fifo_yaml = file("fifo.yaml");
  ASSERT_EQ(::mkfifo(fifo_yaml.c_str(), 0600), 0);
  expectMapError([&] { io::loadMapFile(fifo_yaml); }, fifo_yaml, 0, "FIFO");
  fs::create_directories(file("dir.poly"));
  expectMapError([&] { core::loadPolyFile(file("dir.poly")); }, file("dir.poly"), 0, "directory");
  // An image that is a FIFO or a directory.
  const std::string image_fifo = file("image.pgm");
  ASSERT_EQ(::mkfifo(image_fifo.c_str(), 0600), 0);
  const std::string y = yaml("image.pgm");
  expectMapError([&] { io::loadOccupancyGridYaml(y); }, image_fifo, 0, "regular file");
  fs::create_directories(file("image_dir.png"));
  const std::string y2 = yaml("image_dir.png");
  expectMapError([&] { io::loadOccupancyGridYaml(y2); }, file("image_dir.png"), 0, "regular file");
}

TEST_F(MapFilesHardening, TruncatedPgmNamesTheImage)
{
  const std::string y = gridYaml();
  ASSERT_NO_THROW(io::loadOccupancyGridYaml(y));
  const std::string pgm = file("map.pgm");
  const auto size = fs::file_size(pgm);
  for (const auto cut : { size - 1, size - 40, size / 2 })
  {
    fs::resize_file(pgm, cut);
    expectMapError([&] { io::loadOccupancyGridYaml(y); }, pgm, 0, "truncated");
    expectMapError([&] { io::loadMapFile(y); }, pgm, 0, y);
  }
}

TEST_F(MapFilesHardening, HugeImagesAreRefusedFromTheHeader)
{
  // A PGM announcing 20,000 x 20,000 pixels (400 M cells) with a few bytes of data.
  const std::string pgm = write("huge.pgm", "P5\n20000 20000\n255\n" + std::string(64, '\0'));
  const std::string y = yaml("huge.pgm");
  expectMapError([&] { io::loadOccupancyGridYaml(y); }, pgm, 0, "beyond the limit");
  // A PNG whose header says 20,000 x 20,000: a real 4 x 4 PNG with its IHDR size patched.
  const std::vector<unsigned char> pixels(16, 255);
  ASSERT_TRUE(stbi_write_png(file("small.png").c_str(), 4, 4, 1, pixels.data(), 4));
  std::stringstream bytes;
  bytes << std::ifstream(file("small.png"), std::ios::binary).rdbuf();
  std::string png = bytes.str();
  ASSERT_GT(png.size(), 24u);
  const unsigned char side[4] = { 0x00, 0x00, 0x4e, 0x20 };  // 20000, big-endian
  png.replace(16, 4, reinterpret_cast<const char*>(side), 4);
  png.replace(20, 4, reinterpret_cast<const char*>(side), 4);
  const std::string huge_png = write("huge.png", png);
  const std::string y2 = yaml("huge.png");
  expectMapError([&] { io::loadOccupancyGridYaml(y2); }, huge_png, 0, "beyond the limit");
  EXPECT_THROW(io::readImageInfo(huge_png), MapError);
  // Within the limits, the size comes from the header.
  const io::ImageInfo info = io::readImageInfo(file("small.png"));
  EXPECT_EQ(info.width, 4);
  EXPECT_EQ(info.height, 4);
  EXPECT_EQ(info.channels, 1);
}

}  // namespace fdml_localization
