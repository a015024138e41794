// Topology-safe Douglas-Peucker on rings: the tolerance bound, the validity checks, and the
// tightening of just the rings that would otherwise cross.
#include "fdml_localization/core/map/polygon_map.h"
#include "fdml_localization/core/map/ring_simplify.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace core = fdml_localization::core;
using core::Vec2;

namespace
{
double uniform(std::mt19937_64& rng)
{
  return static_cast<double>(rng() >> 11) * (1.0 / 9007199254740992.0);
}
}  // namespace

TEST(RingSimplify, DouglasPeuckerKeepsEveryDroppedVertexWithinTolerance)
{
  std::mt19937_64 rng(3);
  core::Ring ring;
  for (int i = 0; i < 400; ++i)
  {
    const double a = core::kTwoPi * i / 400;
    const double r = 2.0 + 0.05 * uniform(rng) + 0.3 * std::sin(5 * a);
    ring.push_back(Vec2(r * std::cos(a), r * std::sin(a)));
  }
  for (double tol : { 0.01, 0.05, 0.2 })
  {
    const core::Ring simple = core::simplifyRing(ring, tol);
    EXPECT_LT(simple.size(), ring.size());
    for (const Vec2& p : ring)
    {
      double best = core::kInf;
      for (std::size_t i = 0, j = simple.size() - 1; i < simple.size(); j = i++)
      {
        best = std::min(best, core::pointSegmentDistanceSquared(p, core::Segment{ simple[j], simple[i] }));
      }
      EXPECT_LE(std::sqrt(best), tol + 1e-12);
    }
  }
}

TEST(RingSimplify, FindsCrossingTouchingAndMisplacedRings)
{
  const core::Ring outer = { { 0, 0 }, { 10, 0 }, { 10, 10 }, { 0, 10 } };
  const core::Ring hole = { { 2, 2 }, { 2, 4 }, { 4, 4 }, { 4, 2 } };
  EXPECT_EQ(core::findInvalidRings({ outer, hole }), (std::vector<bool>{ false, false }));
  const core::Ring bowtie = { { 0, 0 }, { 10, 10 }, { 10, 0 }, { 0, 10 } };
  EXPECT_EQ(core::findInvalidRings({ bowtie }), (std::vector<bool>{ true }));
  const core::Ring outside = { { 12, 2 }, { 12, 4 }, { 14, 4 }, { 14, 2 } };
  // A hole outside flags the outer ring too: either may be the one that moved.
  EXPECT_EQ(core::findInvalidRings({ outer, hole, outside }), (std::vector<bool>{ true, false, true }));
  const core::Ring inner = { { 2.5, 2.5 }, { 2.5, 3 }, { 3, 3 }, { 3, 2.5 } };
  EXPECT_EQ(core::findInvalidRings({ outer, hole, inner }), (std::vector<bool>{ false, true, true }));
  const core::Ring touching = { { 4, 3 }, { 4, 5 }, { 6, 5 }, { 6, 3 } };  // shares an edge part
  EXPECT_EQ(core::findInvalidRings({ outer, hole, touching }), (std::vector<bool>{ false, true, true }));
  const core::Ring spike = { { 0, 0 }, { 10, 0 }, { 5, 0 }, { 5, 5 } };
  EXPECT_EQ(core::findInvalidRings({ spike }), (std::vector<bool>{ true }));
}

TEST(RingSimplify, TightensOnlyTheRingsThatWouldCross)
{
  // A hole in a shallow dent of the top wall: at tolerance 0.3 the dent is straightened away
  // and the hole would end up outside; both rings must be kept tighter.
  const core::Ring outer = { { 0, 0 }, { 10, 0 }, { 10, 5 }, { 6, 5 }, { 5, 5.25 }, { 4, 5 }, { 0, 5 } };
  const core::Ring hole = { { 4.9, 5.05 }, { 4.9, 5.15 }, { 5.1, 5.15 }, { 5.1, 5.05 } };
  ASSERT_EQ(core::findInvalidRings({ outer, hole }), (std::vector<bool>{ false, false }));
  ASSERT_EQ(core::simplifyRing(outer, 0.3).size(), 4u);
  ASSERT_EQ(core::findInvalidRings({ core::simplifyRing(outer, 0.3), hole }), (std::vector<bool>{ true, true }));
  core::SimplifyStats stats;
  const std::vector<core::Ring> out = core::simplifyRings({ outer, hole }, 0.3, &stats);
  EXPECT_TRUE(stats.valid);
  EXPECT_EQ(stats.rings_tightened, 2);
  EXPECT_EQ(out[0].size(), 7u);
  const std::vector<bool> bad = core::findInvalidRings(out);
  EXPECT_EQ(bad, (std::vector<bool>{ false, false }));
  EXPECT_NO_THROW(core::PolygonMap::fromRings(out));
}
