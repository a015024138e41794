// validateRings (a grid of edges, O(n log n)) against the previous check (Boost.Geometry's
// is_valid, ring_validation_reference.h) on random small rings on a lattice, which cross,
// touch, overlap and nest often; and on large rings, which the previous check took minutes for.
#include "fdml_localization/core/map/map_io.h"

#include "ring_validation_reference.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
/// A ring of @p n lattice points around @p centre, in angle order (star-shaped: often simple,
/// sometimes touching or collinear once rounded to the lattice).
Ring starRing(std::mt19937_64& rng, const Vec2& centre, int n, double r_min, double r_max)
{
  std::uniform_real_distribution<double> radius(r_min, r_max);
  std::uniform_real_distribution<double> jitter(-0.4, 0.4);
  Ring ring;
  for (int i = 0; i < n; ++i)
  {
    const double a = 2.0 * M_PI * (i + 0.5 + jitter(rng)) / n;
    const double r = radius(rng);
    ring.emplace_back(std::round(centre.x() + r * std::cos(a)), std::round(centre.y() + r * std::sin(a)));
  }
  return ring;
}

/// A ring of @p n arbitrary lattice points in [0, size]^2 (mostly crossing itself).
Ring randomRing(std::mt19937_64& rng, int n, int size)
{
  std::uniform_int_distribution<int> coordinate(0, size);
  Ring ring;
  for (int i = 0; i < n; ++i)
  {
    ring.emplace_back(coordinate(rng), coordinate(rng));
  }
  return ring;
}

std::vector<Ring> randomMap(std::mt19937_64& rng)
{
  std::uniform_int_distribution<int> kind(0, 9);
  std::uniform_int_distribution<int> count(3, 7);
  std::uniform_int_distribution<int> holes(0, 3);
  std::uniform_real_distribution<double> place(1.0, 9.0);
  std::vector<Ring> rings;
  rings.push_back(kind(rng) < 2 ? randomRing(rng, count(rng), 10) : starRing(rng, Vec2(5, 5), count(rng), 3.0, 6.0));
  for (int h = holes(rng); h > 0; --h)
  {
    rings.push_back(kind(rng) < 1 ? randomRing(rng, count(rng) - 1, 10) :
                                    starRing(rng, Vec2(place(rng), place(rng)), count(rng) - 1, 0.6, 2.2));
  }
  return rings;
}

std::string describe(const std::vector<Ring>& rings)
{
  std::ostringstream os;
  for (const Ring& ring : rings)
  {
    for (const Vec2& v : ring)
    {
      os << v.x() << " " << v.y() << "\n";
    }
    os << "\n";
  }
  return os.str();
}

/// A simple ring of @p n vertices: a circle of radius 100 m with 1 cm of random radial noise.
Ring largeRing(int n, std::uint64_t seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> radius(99.99, 100.0);
  Ring ring;
  for (int i = 0; i < n; ++i)
  {
    const double a = 2.0 * M_PI * i / n;
    const double r = radius(rng);
    ring.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return ring;
}
}  // namespace

TEST(RingValidation, SameVerdictsAsTheBoostCheckOnRandomLatticeMaps)
{
  std::mt19937_64 rng(20261124);
  int valid = 0;
  int invalid_alone = 0;
  int invalid_together = 0;
  for (int trial = 0; trial < 20000; ++trial)
  {
    const std::vector<Ring> rings = randomMap(rng);
    const long expected = test::referenceVerdict(rings);
    const std::vector<RingIssue> issues = validateRings(rings);
    if (expected < 0)
    {
      ++valid;
      ASSERT_TRUE(issues.empty()) << "trial " << trial << ": " << issues.front().reason << "\n" << describe(rings);
      continue;
    }
    ASSERT_FALSE(issues.empty()) << "trial " << trial << ": valid, expected invalid\n" << describe(rings);
    if (expected < static_cast<long>(rings.size()))
    {
      ++invalid_alone;
      EXPECT_EQ(issues.front().ring, static_cast<std::size_t>(expected)) << issues.front().reason;
    }
    else
    {
      ++invalid_together;
    }
  }
  // The generator covers all three verdicts well.
  EXPECT_GT(valid, 2000);
  EXPECT_GT(invalid_alone, 2000);
  EXPECT_GT(invalid_together, 2000);
}

TEST(RingValidation, TouchingRings)
{
  const Ring outer{ Vec2(0, 0), Vec2(10, 0), Vec2(10, 10), Vec2(0, 10) };
  // A hole touching the outer ring at one point: valid (the free space stays connected).
  EXPECT_TRUE(validateRings({ outer, { Vec2(0, 5), Vec2(3, 4), Vec2(3, 6) } }).empty());
  // Touching it at two points cuts the free space in two.
  EXPECT_FALSE(validateRings({ outer, { Vec2(0, 5), Vec2(10, 5), Vec2(5, 6) } }).empty());
  // Two holes touching each other once: valid; sharing an edge: invalid.
  EXPECT_TRUE(
      validateRings({ outer, { Vec2(2, 2), Vec2(4, 2), Vec2(4, 4) }, { Vec2(4, 4), Vec2(6, 4), Vec2(6, 6) } }).empty());
  EXPECT_FALSE(validateRings({ outer,
                               { Vec2(2, 2), Vec2(4, 2), Vec2(4, 4), Vec2(2, 4) },
                               { Vec2(4, 2), Vec2(6, 2), Vec2(6, 4), Vec2(4, 4) } })
                   .empty());
  // A ring touching itself (a pinch) is not simple.
  EXPECT_FALSE(validateRings({ { Vec2(0, 0), Vec2(4, 0), Vec2(2, 2), Vec2(4, 4), Vec2(0, 4), Vec2(2, 2) } }).empty());
}

TEST(RingValidation, LargeRingsAreValidatedAndTheirCrossingsFound)
{
  const Ring ring = largeRing(100000, 7);
  EXPECT_TRUE(validateRings({ ring }).empty());
  // Move vertex 70001 a quarter turn on and out to 150 m: the edge from vertex 70000 to it cuts
  // through the inside (it passes within 83 m of the centre) and crosses the ring on its way out.
  Ring crossed = ring;
  const double a = 2.0 * M_PI * 70001 / 100000 + M_PI / 2;
  crossed[70001] = Vec2(150.0 * std::cos(a), 150.0 * std::sin(a));
  const std::vector<RingIssue> issues = validateRings({ crossed });
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues.front().ring, 0u);
  EXPECT_EQ(issues.front().vertex, 70000u);
  EXPECT_NE(issues.front().reason.find("crosses itself"), std::string::npos) << issues.front().reason;
  // As a hole inside a larger square, with a hole crossing it.
  const Ring outer{ Vec2(-200, -200), Vec2(200, -200), Vec2(200, 200), Vec2(-200, 200) };
  EXPECT_TRUE(validateRings({ outer, ring }).empty());
  const std::vector<RingIssue> crossing =
      validateRings({ outer, ring, { Vec2(95, -1), Vec2(120, -1), Vec2(120, 1), Vec2(95, 1) } });
  ASSERT_FALSE(crossing.empty());
  EXPECT_EQ(crossing.front().ring, 2u);
}

/// Radii in [5, 10] m at evenly spaced angles: every edge runs beside thousands of others,
/// the case where Boost (and an edge grid) are quadratic and the sweep line is not.
Ring zigzagRing(int n)
{
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> radius(5.0, 10.0);
  Ring ring;
  for (int i = 0; i < n; ++i)
  {
    const double a = 2.0 * M_PI * i / n;
    const double r = radius(rng);
    ring.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  return ring;
}

TEST(RingValidation, DenseZigzagRingsAreValidated)
{
  EXPECT_TRUE(validateRings({ zigzagRing(100000) }).empty());
  // Vertex 5000 of 10,000 moved a quarter turn on, 15 m out: the edge to it from vertex 4999
  // passes within 8.4 m of the centre, through the zigzags, and crosses them. (Placing a
  // crossing falls back on the edge grid: quadratic on such a ring, hence the smaller n.)
  Ring ring = zigzagRing(10000);
  const double a = 2.0 * M_PI * 5000 / 10000 + M_PI / 2;
  ring[5000] = Vec2(15.0 * std::cos(a), 15.0 * std::sin(a));
  const std::vector<RingIssue> issues = validateRings({ ring });
  ASSERT_FALSE(issues.empty());
  EXPECT_EQ(issues.front().vertex, 4999u);
  EXPECT_NE(issues.front().reason.find("crosses itself"), std::string::npos) << issues.front().reason;
}

TEST(RingValidation, HugeCoordinatesAreRefused)
{
  const std::vector<RingIssue> issues = validateRings({ { Vec2(0, 0), Vec2(1e19, 0), Vec2(0, 1) } });
  ASSERT_EQ(issues.size(), 1u);
  EXPECT_EQ(issues.front().vertex, 1u);
  EXPECT_NE(issues.front().reason.find("1e9"), std::string::npos) << issues.front().reason;
}

}  // namespace core
}  // namespace fdml_localization
