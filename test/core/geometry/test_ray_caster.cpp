// The grid ray cast against the brute-force loop over every edge (>= 100,000 rays per map,
// including rays through vertices and rays parallel to edges), and accelerated free-space and
// box queries against brute force. Scene casts are in test_scene.cpp.
#include "fdml_localization/simulation/map_generators.h"
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/geometry/ray_caster.h"

#include "test_util.h"

#include <gtest/gtest.h>

#include <random>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
struct NamedMap
{
  std::string name;
  PolygonMap map;
};

std::vector<NamedMap> allMaps()
{
  std::vector<NamedMap> maps;
  for (const std::string& path : test::bundledMaps())
  {
    maps.push_back({ test::baseName(path), loadPolyFile(path) });
  }
  for (std::uint64_t seed : { 1, 2, 3 })
  {
    maps.push_back({ "random70 seed " + std::to_string(seed), randomPolygon(70, 1.0, 0.5, seed).scaled(2.0) });
  }
  maps.push_back({ "random300 noisy", randomPolygon(300, 5.0, 0.9, 4) });
  BuildingOptions options;
  options.seed = 5;
  maps.push_back({ "building 60x40", generateBuilding(options) });
  return maps;
}

/// Compares grid and brute-force casts, counting disagreements and keeping the first few.
class CastChecker
{
public:
  explicit CastChecker(const SegmentGrid& grid) : grid_(grid)
  {}

  void check(const Vec2& origin, const Vec2& dir, double max_range = kInf)
  {
    ++rays_;
    const RayHit fast = grid_.cast(origin, dir, max_range);
    const RayHit slow = grid_.castBruteForce(origin, dir, max_range);
    std::string problem;
    if (fast.hit() != slow.hit())
    {
      problem = "hit differs";
    }
    else if (fast.hit())
    {
      const Segment& seg = grid_.segments()[fast.segment];
      if (std::abs(fast.distance - slow.distance) > 1e-9)
      {
        problem = "distance differs";
      }
      else if (fast.segment != slow.segment && std::abs(raySegmentDistance(origin, dir, seg) - slow.distance) > 1e-9)
      {
        problem = "segment differs";
      }
      else if (!(fast.distance >= 0.0) || fast.distance > max_range)
      {
        problem = "distance out of [0, max_range]";
      }
      else if (pointSegmentDistanceSquared(origin + fast.distance * dir, seg) > 1e-18 * (1.0 + fast.distance))
      {
        problem = "hit point not on the segment";
      }
      ++hits_;
    }
    if (!problem.empty() && failures_++ < 5)
    {
      std::ostringstream os;
      os.precision(17);
      os << problem << ": origin (" << origin.x() << ", " << origin.y() << ") dir (" << dir.x() << ", " << dir.y()
         << ") max " << max_range << ": grid " << fast.distance << " seg " << fast.segment << ", brute "
         << slow.distance << " seg " << slow.segment << "\n";
      report_ += os.str();
    }
  }

  int rays() const
  {
    return rays_;
  }
  int hits() const
  {
    return hits_;
  }
  int failures() const
  {
    return failures_;
  }
  const std::string& report() const
  {
    return report_;
  }

private:
  const SegmentGrid& grid_;
  int rays_ = 0;
  int hits_ = 0;
  int failures_ = 0;
  std::string report_;
};

/// Random draws for the ray kinds: points around the map, angles, edges.
struct RayDraw
{
  RayDraw(const PolygonMap& map, std::uint64_t seed)
    : rng(seed)
    , ux(map.bounds().min.x() - 0.1 * map.bounds().size().x(), map.bounds().max.x() + 0.1 * map.bounds().size().x())
    , uy(map.bounds().min.y() - 0.1 * map.bounds().size().y(), map.bounds().max.y() + 0.1 * map.bounds().size().y())
    , edges(map.edges())
  {}
  Vec2 point()
  {
    return Vec2(ux(rng), uy(rng));
  }
  const Segment& edge()
  {
    return edges[rng() % edges.size()];
  }

  std::mt19937_64 rng;
  std::uniform_real_distribution<double> ux;
  std::uniform_real_distribution<double> uy;
  std::uniform_real_distribution<double> angle{ -kPi, kPi };
  std::uniform_real_distribution<double> unit{ 0.0, 1.0 };
  const std::vector<Segment>& edges;
};

/// Random rays from inside and outside the map, with and without a range, and axis-aligned ones.
void checkRandomRays(RayDraw& draw, const Box2& b, CastChecker& checker)
{
  std::mt19937_64& rng = draw.rng;
  auto random_point = [&] { return draw.point(); };
  auto& angle = draw.angle;
  auto& unit = draw.unit;
  // 1. Random rays from inside and outside the map.
  for (int i = 0; i < 50000; ++i)
  {
    checker.check(random_point(), test::unitDir(angle(rng)));
  }
  // 2. Random rays with a finite range.
  for (int i = 0; i < 10000; ++i)
  {
    checker.check(random_point(), test::unitDir(angle(rng)), 3.0 * unit(rng) * b.size().maxCoeff());
  }
  // 3. Axis-aligned rays, some along the lines of vertices (along walls of rectilinear maps).
  const Vec2 axes[4] = { Vec2(1, 0), Vec2(0, 1), Vec2(-1, 0), Vec2(0, -1) };
  for (int i = 0; i < 10000; ++i)
  {
    Vec2 o = random_point();
    const Segment& e = draw.edge();
    if (i % 2 == 0)
    {
      o.y() = e.a.y();
    }
    else
    {
      o.x() = e.a.x();
    }
    checker.check(o, axes[i % 4]);
  }
}

/// Rays through and from vertices, and rays parallel to edges.
void checkVertexAndParallelRays(RayDraw& draw, CastChecker& checker)
{
  std::mt19937_64& rng = draw.rng;
  auto random_point = [&] { return draw.point(); };
  auto& angle = draw.angle;
  auto& unit = draw.unit;
  // 4. Rays through vertices from random origins, and rays leaving a vertex.
  for (int i = 0; i < 15000; ++i)
  {
    const Segment& e = draw.edge();
    const Vec2 o = random_point();
    if ((e.a - o).norm() > 1e-9)
    {
      checker.check(o, (e.a - o).normalized());
    }
    checker.check(e.a, test::unitDir(angle(rng)));
  }
  // 5. Rays parallel to edges: on the edge's line (collinear, from before, inside and after the
  //    edge, both ways, starting at its endpoints) and at small and large offsets from it.
  const double offsets[] = { 0.0, 1e-12, -1e-12, 1e-9, -1e-9, 1e-3, -1e-3, 0.25, -0.25 };
  for (int i = 0; i < 15000; ++i)
  {
    const Segment& e = draw.edge();
    const Vec2 along = (e.b - e.a).normalized();
    const Vec2 normal(-along.y(), along.x());
    const double s = -1.0 + 3.0 * unit(rng);
    const Vec2 base = (i % 5 == 0) ? e.a : (i % 5 == 1) ? e.b : Vec2(e.a + s * (e.b - e.a));
    const Vec2 o = base + offsets[i % 9] * normal;
    checker.check(o, (i % 2 == 0) ? along : Vec2(-along));
  }
}

/// Casts >= 100,000 rays of several kinds on @p map.
void checkMapRays(const NamedMap& named, const SegmentGrid& grid, std::uint64_t seed)
{
  RayDraw draw(named.map, seed);
  CastChecker checker(grid);
  checkRandomRays(draw, named.map.bounds(), checker);
  checkVertexAndParallelRays(draw, checker);
  EXPECT_GE(checker.rays(), 100000) << named.name;
  EXPECT_GT(checker.hits(), checker.rays() / 4) << named.name;
  EXPECT_EQ(checker.failures(), 0) << named.name << " (" << grid.segments().size() << " edges, cell " << grid.cellSize()
                                   << " m):\n"
                                   << checker.report();
}
}  // namespace

TEST(RayCaster, GridEqualsBruteForceOnEveryMap)
{
  std::uint64_t seed = 100;
  for (const NamedMap& named : allMaps())
  {
    SCOPED_TRACE(named.name);
    const MapRayCaster caster(named.map);
    ASSERT_EQ(caster.grid().segments().size(), named.map.edges().size());
    checkMapRays(named, caster.grid(), ++seed);
  }
}

TEST(RayCaster, GridEqualsBruteForceForOtherCellSizes)
{
  const PolygonMap office = loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/office.poly");
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> ux(-1.0, 21.0), uy(-1.0, 13.0), angle(-kPi, kPi);
  for (double cell : { 0.013, 0.3, 7.0, 100.0 })
  {
    const SegmentGrid grid(office.edges(), cell);
    CastChecker checker(grid);
    for (int i = 0; i < 10000; ++i)
    {
      checker.check(Vec2(ux(rng), uy(rng)), test::unitDir(angle(rng)));
    }
    EXPECT_EQ(checker.failures(), 0) << "cell " << cell << ":\n" << checker.report();
  }
}

TEST(RayCaster, KnownRangesInTheSquareRoom)
{
  const MapRayCaster caster(loadPolyFile(std::string(FDML_SOURCE_DIR) + "/maps/square_room.poly"));
  EXPECT_NEAR(caster.range(Pose2(0, 0, 0)), 1.0, 1e-12);
  EXPECT_NEAR(caster.range(Pose2(0.5, 0, kPi)), 1.5, 1e-12);
  EXPECT_NEAR(caster.range(Pose2(0, 0, kPi / 4)), std::sqrt(2.0), 1e-12);  // into the corner
  EXPECT_NEAR(caster.range(Pose2(0.2, -0.3, kPi / 2)), 1.3, 1e-12);
  EXPECT_EQ(caster.range(Pose2(0, 0, 0), 0.5), kInf);  // beyond max_range
  EXPECT_EQ(caster.range(Pose2(5, 0, 0)), kInf);       // outside, pointing away
  EXPECT_NEAR(caster.range(Pose2(5, 0, kPi)), 4.0, 1e-12);
  EXPECT_TRUE(caster.isFree(Vec2(0.9, -0.9)));
  EXPECT_FALSE(caster.isFree(Vec2(1.1, 0)));
}

TEST(RayCaster, RaysFromFreeSpaceAlwaysHit)
{
  for (const NamedMap& named : allMaps())
  {
    const MapRayCaster caster(named.map);
    std::mt19937_64 rng(31);
    const Box2& b = named.map.bounds();
    std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()), angle(-kPi, kPi);
    int tested = 0;
    for (int i = 0; i < 20000 && tested < 2000; ++i)
    {
      const Vec2 p(ux(rng), uy(rng));
      if (!caster.isFree(p))
      {
        continue;
      }
      ++tested;
      const double d = caster.range(Pose2(p.x(), p.y(), angle(rng)));
      ASSERT_TRUE(std::isfinite(d) && d > 0.0) << named.name << " at " << p.transpose();
    }
    EXPECT_GE(tested, 200) << named.name;
  }
}

TEST(RayCaster, IsFreeEqualsBruteForce)
{
  for (const NamedMap& named : allMaps())
  {
    SCOPED_TRACE(named.name);
    const MapRayCaster caster(named.map);
    std::mt19937_64 rng(41);
    const Box2& b = named.map.bounds();
    const Vec2 pad = 0.1 * b.size();
    std::uniform_real_distribution<double> ux(b.min.x() - pad.x(), b.max.x() + pad.x());
    std::uniform_real_distribution<double> uy(b.min.y() - pad.y(), b.max.y() + pad.y());
    std::uniform_real_distribution<double> angle(-kPi, kPi);
    const std::vector<Segment>& edges = named.map.edges();
    int free_points = 0, mismatches = 0;
    for (int i = 0; i < 40000; ++i)
    {
      Vec2 p(ux(rng), uy(rng));
      const Segment& e = edges[rng() % edges.size()];
      if (i % 4 == 1)
      {
        p.y() = e.a.y();  // on the horizontal line of a vertex: the half-open crossing rule
      }
      else if (i % 4 == 2)
      {
        p = e.a + 1e-7 * test::unitDir(angle(rng));  // next to a vertex
      }
      bool on_boundary = false;
      for (const Segment& s : edges)
      {
        on_boundary = on_boundary || pointSegmentDistanceSquared(p, s) < 1e-24;
      }
      if (on_boundary)
      {
        continue;  // either answer is allowed on the boundary
      }
      const bool expected = named.map.containsBruteForce(p);
      free_points += expected ? 1 : 0;
      if (caster.isFree(p) != expected && mismatches++ < 5)
      {
        ADD_FAILURE() << "isFree(" << p.x() << ", " << p.y() << ") != " << expected;
      }
    }
    EXPECT_EQ(mismatches, 0);
    EXPECT_GT(free_points, 1000);
  }
}

// isFree() remembers a thread's last verdict: one point asked of maps in turn gets each one's own.
TEST(RayCaster, IsFreeOfOnePointOnSeveralMaps)
{
  const Ring outer{ Vec2(0.0, 0.0), Vec2(10.0, 0.0), Vec2(10.0, 10.0), Vec2(0.0, 10.0) };
  const Ring pillar{ Vec2(4.0, 4.0), Vec2(4.0, 6.0), Vec2(6.0, 6.0), Vec2(6.0, 4.0) };
  const MapRayCaster open(PolygonMap::fromRings({ outer }));
  const MapRayCaster pillared(PolygonMap::fromRings({ outer, pillar }));  // same bounds
  const MapRayCaster copy = open;
  MapRayCaster assigned(PolygonMap::fromRings({ outer }));
  assigned = pillared;
  const Vec2 p(5.0, 5.0);
  for (int round = 0; round < 3; ++round)
  {
    EXPECT_TRUE(open.isFree(p) && open.isFree(p));
    EXPECT_FALSE(pillared.isFree(p));
    EXPECT_TRUE(copy.isFree(p) && open.isFree(p));
    EXPECT_FALSE(assigned.isFree(p) || assigned.isFree(p) || !pillared.isFree(Vec2(2.0, 2.0)));
  }
}

TEST(RayCaster, BoxQueriesEqualBruteForce)
{
  for (const NamedMap& named : allMaps())
  {
    SCOPED_TRACE(named.name);
    const MapRayCaster caster(named.map);
    const SegmentGrid& grid = caster.grid();
    std::mt19937_64 rng(51);
    const Box2& b = named.map.bounds();
    std::uniform_real_distribution<double> ux(b.min.x() - 1, b.max.x() + 1), uy(b.min.y() - 1, b.max.y() + 1);
    std::uniform_real_distribution<double> size(0.0, 0.1 * b.size().maxCoeff());
    for (int i = 0; i < 2000; ++i)
    {
      Box2 box;
      box.extend(Vec2(ux(rng), uy(rng)));
      box.extend(box.min + Vec2(size(rng), size(rng)));
      std::vector<int> expected;
      for (std::size_t s = 0; s < grid.segments().size(); ++s)
      {
        if (segmentIntersectsBox(grid.segments()[s], box))
        {
          expected.push_back(static_cast<int>(s));
        }
      }
      std::vector<int> got;
      grid.forEachSegmentInBox(box, [&got](int s) {
        got.push_back(s);
        return true;
      });
      std::sort(got.begin(), got.end());
      ASSERT_EQ(got, expected) << "box " << box.min.transpose() << " .. " << box.max.transpose();
      ASSERT_EQ(grid.anySegmentInBox(box), !expected.empty());
    }
  }
}

}  // namespace core
}  // namespace fdml_localization
