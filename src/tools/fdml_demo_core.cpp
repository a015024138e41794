// Interim demo of the core library: loads a map, takes k range readings from a random free
// pose (turning in place), and prints them next to the exact ray casts.
#include "fdml_localization/core/map/map_io.h"
#include "fdml_localization/core/geometry/ray_caster.h"

#include <cstdio>
#include <exception>
#include <random>

int main(int argc, char** argv)
{
  namespace core = fdml_localization::core;
  if (argc < 2)
  {
    std::fprintf(stderr, "usage: fdml_demo_core MAP.poly [SEED]\n");
    return 2;
  }
  try
  {
    const core::MapRayCaster map(core::loadPolyFile(argv[1]));
    std::mt19937_64 rng(argc > 2 ? std::stoull(argv[2]) : 1);
    const core::Box2& b = map.map().bounds();
    std::uniform_real_distribution<double> ux(b.min.x(), b.max.x()), uy(b.min.y(), b.max.y()),
        ut(-core::kPi, core::kPi);
    core::Pose2 pose;
    do
    {
      pose = core::Pose2(ux(rng), uy(rng), ut(rng));
    } while (!map.isFree(pose.position()));
    std::printf("map %s: %zu rings, %zu edges, free area %.2f m^2\n", argv[1], map.map().rings().size(),
                map.map().edges().size(), map.map().area());
    std::printf("robot at x=%.3f y=%.3f theta=%.3f\n", pose.x, pose.y, pose.theta);
    for (int i = 0; i < 10; ++i)
    {
      const core::Pose2 sensor = core::compose(pose, core::Pose2(0, 0, i * core::kTwoPi / 10));
      std::printf("reading %d: heading %+.3f rad, range %.3f m\n", i, sensor.theta, map.range(sensor));
    }
    return 0;
  }
  catch (const std::exception& e)
  {
    std::fprintf(stderr, "fdml_demo_core: %s\n", e.what());
    return 2;
  }
}
