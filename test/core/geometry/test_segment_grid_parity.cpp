// The free-space test's fast path (a parity per cell centre, segment_grid_parity.cpp) against
// the row scan it replaces, on every bundled and generated map, at three cell sizes, for random
// points and for the points where the two could part: cell centres and borders, the horizontal
// lines of vertices, points next to vertices and on edges.
#include "fdml_localization/simulation/map_generators.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/geometry/ray_caster.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
std::vector<std::pair<std::string, PolygonMap>> parityMaps()
{
  std::vector<std::pair<std::string, PolygonMap>> maps;
  for (const std::string& path : test::bundledMaps())
  {
    maps.emplace_back(test::baseName(path), loadPolyFile(path));
  }
  maps.emplace_back("random300 noisy", randomPolygon(300, 5.0, 0.9, 4));
  BuildingOptions options;
  options.seed = 5;
  maps.emplace_back("building 60x40", generateBuilding(options));
  return maps;
}

/// Points where the fast path and the row scan could disagree, and random ones.
std::vector<Vec2> probePoints(const SegmentGrid& grid, std::mt19937_64& rng)
{
  const Box2& b = grid.bounds();
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()), unit(0.0, 1.0);
  std::vector<Vec2> points;
  const double c = grid.cellSize();
  for (int i = 0; i < 4000; ++i)
  {
    const Vec2 p(ux(rng), uy(rng));
    const Vec2 cell = b.min + c * Vec2(std::floor((p.x() - b.min.x()) / c), std::floor((p.y() - b.min.y()) / c));
    const Segment& s = grid.segments()[rng() % grid.segments().size()];
    switch (i % 6)
    {
      case 0:
        points.push_back(p);
        break;
      case 1:
        points.push_back(cell + 0.5 * Vec2(c, c));
        break;  // a cell centre
      case 2:
        points.emplace_back(cell.x(), p.y());
        break;  // a cell border
      case 3:
        points.emplace_back(p.x(), s.a.y());
        break;  // a vertex's horizontal line
      case 4:
        points.push_back(s.a + 1e-7 * (p - s.a).normalized());
        break;  // next to a vertex
      default:
        points.push_back(s.a + unit(rng) * (s.b - s.a));
        break;  // on an edge
    }
  }
  return points;
}
}  // namespace

TEST(SegmentGridParity, EqualsTheRowScanAtEveryCellSize)
{
  std::mt19937_64 rng(16);
  for (const auto& named : parityMaps())
  {
    SCOPED_TRACE(named.first);
    const double automatic = SegmentGrid(named.second.edges()).cellSize();
    for (const double cell : { automatic, 0.25 * automatic, 20.0 * automatic })
    {
      const SegmentGrid grid(named.second.edges(), cell);
      int mismatches = 0;
      int odd = 0;
      for (const Vec2& p : probePoints(grid, rng))
      {
        const bool expected = grid.crossingsToRight(p) % 2 == 1;
        odd += expected ? 1 : 0;
        if (grid.oddCrossingsToRight(p) != expected && mismatches++ < 5)
        {
          ADD_FAILURE() << "cell " << cell << ": parity at (" << p.x() << ", " << p.y() << ") != " << expected;
        }
      }
      EXPECT_EQ(mismatches, 0);
      EXPECT_GT(odd, 400);  // inside points were tested
    }
  }
}

TEST(SegmentGridParity, OutsideTheGridIsEven)
{
  const PolygonMap map = loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/square_room.poly");
  const SegmentGrid grid(map.edges());
  EXPECT_FALSE(grid.oddCrossingsToRight(Vec2(-50.0, 0.0)));
  EXPECT_FALSE(grid.oddCrossingsToRight(Vec2(0.0, 50.0)));
  EXPECT_TRUE(grid.oddCrossingsToRight(Vec2(0.0, 0.0)));
  EXPECT_FALSE(SegmentGrid(std::vector<Segment>()).oddCrossingsToRight(Vec2(0.0, 0.0)));
}

TEST(SegmentCrossing, ProperDegenerateAndNone)
{
  const Vec2 a(0.0, -1.0), b(0.0, 1.0);
  EXPECT_EQ(segmentCrossing(Vec2(-1, 0), Vec2(1, 0), a, b, 1e-9), Crossing::Proper);
  EXPECT_EQ(segmentCrossing(Vec2(-1, 0), Vec2(-0.5, 0), a, b, 1e-9), Crossing::None);
  EXPECT_EQ(segmentCrossing(Vec2(-1, 2), Vec2(1, 2), a, b, 1e-9), Crossing::None);
  EXPECT_EQ(segmentCrossing(Vec2(0, 0), Vec2(1, 0), a, b, 1e-9), Crossing::Degenerate);      // an end on the edge
  EXPECT_EQ(segmentCrossing(Vec2(-1, 1), Vec2(1, 1), a, b, 1e-9), Crossing::Degenerate);     // through a vertex
  EXPECT_EQ(segmentCrossing(Vec2(0, 5), Vec2(0, 6), a, b, 1e-9), Crossing::None);            // collinear, apart
  EXPECT_EQ(segmentCrossing(Vec2(1e-12, 0), Vec2(1, 0), a, b, 1e-9), Crossing::Degenerate);  // within tolerance
}

}  // namespace core
}  // namespace fdml_localization
