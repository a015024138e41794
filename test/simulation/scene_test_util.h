// Independent references for scene casts, shared by the scene tests: ray/disc and ray/polygon
// distances written apart from the library, random obstacles, and the brute-force scene ray.
#pragma once

#include "fdml_localization/simulation/scene.h"

#include "test_util.h"

#include <random>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace test
{
/// Independent ray/disc distance (origin outside the disc): project the centre on the ray.
inline double discDistance(const Vec2& o, const Vec2& d, const Vec2& c, double r)
{
  const double s = (c - o).dot(d);
  const double h2 = (c - o).squaredNorm() - s * s;
  if (h2 > r * r)
  {
    return kInf;
  }
  const double t = s - std::sqrt(r * r - h2);
  return t >= 0.0 ? t : kInf;
}

inline double polygonDistance(const Vec2& o, const Vec2& d, const Ring& ring)
{
  double best = kInf;
  for (std::size_t i = 0; i < ring.size(); ++i)
  {
    best = std::min(best, raySegmentDistance(o, d, Segment{ ring[i], ring[(i + 1) % ring.size()] }));
  }
  return best;
}

/// 20 discs and 8 star-shaped (possibly non-convex) polygons of 3 to 7 vertices in @p b.
inline std::vector<Obstacle> randomObstacles(const Box2& b, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y());
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<Obstacle> obstacles;
  for (int i = 0; i < 20; ++i)
  {
    obstacles.push_back(Obstacle::disc(Vec2(ux(rng), uy(rng)), 0.05 + 0.5 * unit(rng)));
  }
  for (int i = 0; i < 8; ++i)
  {
    const Vec2 c(ux(rng), uy(rng));
    const int n = 3 + i % 5;
    Ring ring;
    for (int k = 0; k < n; ++k)
    {
      const double a = kTwoPi * (k + 0.8 * unit(rng)) / n;
      ring.push_back(c + (0.2 + 0.6 * unit(rng)) * unitDir(a));
    }
    obstacles.push_back(Obstacle::polygon(ring));
  }
  return obstacles;
}

inline bool insideAnyObstacle(const Vec2& p, const std::vector<Obstacle>& obstacles)
{
  for (const Obstacle& o : obstacles)
  {
    const bool inside =
        o.shape == Obstacle::Shape::Disc ? (p - o.centre).norm() <= o.radius : pointInRing(p, o.vertices);
    if (inside)
    {
      return true;
    }
  }
  return false;
}

/// The nearest hit of a ray by brute force: its distance, and the obstacle hit (-1: the map).
struct BruteHit
{
  double distance = kInf;
  double map_distance = kInf;
  int obstacle = -1;
};

inline BruteHit bruteSceneRay(const MapRayCaster& map, const std::vector<Obstacle>& obstacles, const Vec2& p,
                              const Vec2& d)
{
  BruteHit hit;
  hit.map_distance = map.grid().castBruteForce(p, d).distance;
  hit.distance = hit.map_distance;
  for (std::size_t i = 0; i < obstacles.size(); ++i)
  {
    const Obstacle& o = obstacles[i];
    const double t =
        o.shape == Obstacle::Shape::Disc ? discDistance(p, d, o.centre, o.radius) : polygonDistance(p, d, o.vertices);
    if (t < hit.distance)
    {
      hit.distance = t;
      hit.obstacle = static_cast<int>(i);
    }
  }
  return hit;
}

}  // namespace test
}  // namespace core
}  // namespace fdml_localization
