// Loading, validating and round-tripping `.poly` maps; every malformed input must give a
// MapError naming the file and the line, never a crash.
#include "fdml_localization/core/map/map_io.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <unistd.h>

namespace fdml_localization
{
namespace core
{
namespace
{
/// A file in the system temp directory, removed on destruction.
class TempFile
{
public:
  TempFile(const std::string& name, const std::string& text)
    : path_(
          (std::filesystem::temp_directory_path() / ("fdml_test_" + std::to_string(::getpid()) + "_" + name)).string())
  {
    std::ofstream out(path_);
    out << text;
  }
  ~TempFile()
  {
    std::remove(path_.c_str());
  }
  const std::string& path() const
  {
    return path_;
  }

private:
  std::string path_;
};

void expectSameRings(const PolygonMap& a, const PolygonMap& b, const std::string& what)
{
  ASSERT_EQ(a.rings().size(), b.rings().size()) << what;
  for (std::size_t r = 0; r < a.rings().size(); ++r)
  {
    ASSERT_EQ(a.rings()[r].size(), b.rings()[r].size()) << what << " ring " << r;
    for (std::size_t i = 0; i < a.rings()[r].size(); ++i)
    {
      // 17 significant digits: the round trip is exact.
      ASSERT_EQ(a.rings()[r][i].x(), b.rings()[r][i].x()) << what << " ring " << r << " vertex " << i;
      ASSERT_EQ(a.rings()[r][i].y(), b.rings()[r][i].y()) << what << " ring " << r << " vertex " << i;
    }
  }
  EXPECT_EQ(a.hash(), b.hash()) << what;
}

/// Parses @p text as file @p name and expects a MapError at a line in [line_lo, line_hi].
void expectParseError(const std::string& name, const std::string& text, int line_lo, int line_hi)
{
  std::istringstream in(text);
  try
  {
    parsePoly(in, name);
    ADD_FAILURE() << name << ": no error for malformed input";
  }
  catch (const MapError& e)
  {
    EXPECT_EQ(e.file(), name);
    EXPECT_GE(e.line(), line_lo) << e.what();
    EXPECT_LE(e.line(), line_hi) << e.what();
    const std::string prefix = name + ":" + std::to_string(e.line()) + ": ";
    EXPECT_EQ(std::string(e.what()).rfind(prefix, 0), 0u) << "what() = " << e.what();
    EXPECT_FALSE(e.reason().empty());
  }
  // Through a file as well: the error names the path.
  TempFile file(name, text);
  try
  {
    loadPolyFile(file.path());
    ADD_FAILURE() << file.path() << ": no error for malformed input";
  }
  catch (const MapError& e)
  {
    EXPECT_EQ(e.file(), file.path());
    EXPECT_NE(std::string(e.what()).find(file.path() + ":" + std::to_string(e.line()) + ": "), std::string::npos)
        << e.what();
    EXPECT_GE(e.line(), line_lo) << e.what();
    EXPECT_LE(e.line(), line_hi) << e.what();
  }
}

const char* const kSquare = "0 0\n4 0\n4 4\n0 4\n";
}  // namespace

TEST(MapIo, BundledMapsExist)
{
  const std::vector<std::string> maps = test::bundledMaps();
  std::vector<std::string> names;
  for (const std::string& path : maps)
  {
    names.push_back(test::baseName(path));
  }
  for (const char* required :
       { "square_room.poly", "l_room.poly", "office.poly", "warehouse.poly", "corridor.poly", "apartment.poly" })
  {
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  }
}

TEST(MapIo, BundledMapsLoadValidAndRoundTrip)
{
  for (const std::string& path : test::bundledMaps())
  {
    SCOPED_TRACE(path);
    const PolygonMap map = loadPolyFile(path);
    ASSERT_FALSE(map.empty());
    EXPECT_GT(map.area(), 0.0);
    EXPECT_GT(signedArea(map.outer()), 0.0) << "outer ring must be counter-clockwise";
    for (std::size_t r = 1; r < map.rings().size(); ++r)
    {
      EXPECT_LT(signedArea(map.rings()[r]), 0.0) << "hole " << r << " must be clockwise";
    }
    // Stricter than the library's validation: holes keep apart from each other and the outer ring.
    EXPECT_EQ(test::strictRingProblem(map.rings(), 1e-6), "");

    std::stringstream text;
    writePoly(text, map, "round trip of\n" + path);
    expectSameRings(map, parsePoly(text, "<round trip>"), path + " (stream)");

    TempFile file("round_trip.poly", "");
    savePolyFile(file.path(), map, "saved by test_map_io");
    expectSameRings(map, loadPolyFile(file.path()), path + " (file)");
  }
}

TEST(MapIo, KnownAreasAndHoleCounts)
{
  const std::string dir = std::string(FDML_SOURCE_DIR) + "/maps/";
  const PolygonMap square = loadPolyFile(dir + "square_room.poly");
  EXPECT_NEAR(square.area(), 4.0, 1e-12);
  EXPECT_NEAR(square.bounds().size().x(), 2.0, 1e-12);
  EXPECT_EQ(square.holeCount(), 0u);
  const PolygonMap l_room = loadPolyFile(dir + "l_room.poly");
  EXPECT_NEAR(l_room.area(), 4.0 * 1.6 + 1.8 * 1.4, 1e-9);
  EXPECT_EQ(l_room.outer().size(), 6u);
  const PolygonMap office = loadPolyFile(dir + "office.poly");
  EXPECT_NEAR(office.bounds().size().x(), 20.0, 1e-9);
  EXPECT_NEAR(office.bounds().size().y(), 12.0, 1e-9);
  EXPECT_GE(office.holeCount(), 3u);
  EXPECT_GE(loadPolyFile(dir + "warehouse.poly").holeCount(), 20u);
}

TEST(MapIo, ParsesCommentsBlankLinesAndOrientation)
{
  // Clockwise outer ring, counter-clockwise hole, comments, repeated closing vertex, extra blank lines.
  const std::string text = "# a comment\n\n0 0  # origin\n0 4\n4 4\n4 0\n0 0\n\n\n# hole\n1 1\n2 1\n2 2\n1 2\n";
  std::istringstream in(text);
  const PolygonMap map = parsePoly(in, "inline");
  ASSERT_EQ(map.rings().size(), 2u);
  EXPECT_EQ(map.outer().size(), 4u);
  EXPECT_GT(signedArea(map.outer()), 0.0);
  EXPECT_LT(signedArea(map.rings()[1]), 0.0);
  EXPECT_NEAR(map.area(), 15.0, 1e-12);
}

TEST(MapIo, ReadsThePaperFormat)
{
  // One ring, leading spaces, no trailing newline (as in the paper's public maps).
  std::istringstream in("-1.0 -1.0\n -1.0 1.0\n 1.0 1.0\n 1.0 -1.0");
  const PolygonMap map = parsePoly(in, "paper");
  EXPECT_NEAR(map.area(), 4.0, 1e-12);
}

TEST(MapIo, MalformedInputsNameFileAndLine)
{
  expectParseError("non_numeric.poly", "0 0\n1 0\nabc 1\n", 3, 3);
  expectParseError("half_number.poly", "0 0\n1 0\n1 1x\n", 3, 3);
  expectParseError("one_number.poly", "0 0\n1\n1 1\n", 2, 2);
  expectParseError("three_numbers.poly", "0 0\n1 0 2\n1 1\n", 2, 2);
  expectParseError("nan.poly", "0 0\nnan 0\n1 1\n", 2, 2);
  expectParseError("inf.poly", "0 0\n1 0\n1 inf\n", 3, 3);
  expectParseError("huge.poly", "0 0\n1 0\n1 1e999\n", 3, 3);
  expectParseError("two_vertices.poly", "# header\n0 0\n1 0\n", 2, 3);
  expectParseError("two_vertex_hole.poly", std::string(kSquare) + "\n1 1\n2 2\n", 6, 7);
  expectParseError("duplicates_only.poly", "0 0\n0 0\n1 1\n0 0\n", 1, 4);
  expectParseError("collinear.poly", "0 0\n1 1\n2 2\n", 1, 3);
  expectParseError("self_crossing.poly", "# bow tie\n0 0\n2 2\n2 0\n0 2\n", 2, 5);
  expectParseError("hole_outside.poly", std::string(kSquare) + "\n5 5\n6 5\n6 6\n5 6\n", 6, 9);
  expectParseError("hole_crossing.poly", std::string(kSquare) + "\n3 1\n5 1\n5 2\n3 2\n", 6, 9);
  expectParseError("self_crossing_hole.poly", std::string(kSquare) + "\n1 1\n3 3\n3 1\n1 3\n", 6, 9);
  expectParseError("overlapping_holes.poly",
                   std::string(kSquare) + "\n1 1\n2 1\n2 2\n1 2\n\n1.5 1.5\n3 1.5\n3 3\n1.5 3\n", 6, 14);
  expectParseError("empty.poly", "", 1, 1);
  expectParseError("comments_only.poly", "# nothing\n\n# here\n", 1, 3);
}

TEST(MapIo, MissingFileNamesThePath)
{
  const std::string path = "/nonexistent_dir_fdml/missing.poly";
  try
  {
    loadPolyFile(path);
    FAIL() << "no error for a missing file";
  }
  catch (const MapError& e)
  {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

TEST(MapIo, SaveToUnwritablePathThrows)
{
  std::istringstream in(kSquare);
  const PolygonMap map = parsePoly(in, "square");
  EXPECT_THROW(savePolyFile("/nonexistent_dir_fdml/out.poly", map), std::runtime_error);
}

TEST(MapIo, FromRingsRejectsInvalidRings)
{
  EXPECT_THROW(PolygonMap::fromRings({ { Vec2(0, 0), Vec2(1, 0) } }), MapError);
  EXPECT_THROW(PolygonMap::fromRings({ { Vec2(0, 0), Vec2(2, 2), Vec2(2, 0), Vec2(0, 2) } }), MapError);
  EXPECT_THROW(PolygonMap::fromRings({ { Vec2(0, 0), Vec2(1, 0), Vec2(NAN, 1) } }), MapError);
  EXPECT_TRUE(validateRings({ { Vec2(0, 0), Vec2(1, 0), Vec2(0, 1) } }).empty());
  const auto issues = validateRings(
      { { Vec2(0, 0), Vec2(4, 0), Vec2(4, 4), Vec2(0, 4) }, { Vec2(5, 5), Vec2(6, 5), Vec2(6, 6), Vec2(5, 6) } });
  ASSERT_FALSE(issues.empty());
  EXPECT_EQ(issues.front().ring, 1u);
}

}  // namespace core
}  // namespace fdml_localization
