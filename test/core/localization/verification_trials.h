// The verification suite's trials (issue 16): random trials over reading geometries on small
// maps, noise-free and noisy, rays or cones (verification_checks.h checks them). Shared by the
// fast gtests (test_verification.cpp, ...) and the long `make verify` run (verify_main.cpp).
#pragma once

#include "fdml_localization/core/geometry/cone_cast.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include "localizer_test_utils.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace verification
{
constexpr double kDeg = kPi / 180.0;

enum Geometry
{
  kTurning,   ///< one sensor at the centre turning in place, 2 pi / k apart
  kDriving,   ///< four sensors (front, left, back, right, 0.15 m) driving 1 cm per reading
  kRandom,    ///< one sensor at the centre, random directions
  kGrazing,   ///< turning in place, the first ray aimed within 0.05 deg of a map vertex
  kNoReturn,  ///< turning in place with a max range of 1 to 2.5 m (some readings return nothing)
  kGeometries
};

inline const char* geometryName(int g)
{
  static const char* names[] = { "turning", "driving", "random", "grazing", "no-return" };
  return names[g];
}

/// One trial's inputs.
struct Trial
{
  int map = 0;
  int geometry = kTurning;
  bool noisy = false;
  Pose2 truth;
  std::vector<Reading> readings;
};

/// The small maps of the suite.
inline std::vector<std::shared_ptr<const MapRayCaster>> smallMaps()
{
  return { test::loadMap("maps/l_room.poly"), test::lRoomMap(), test::loadMap("maps/square_room.poly") };
}

/// The options of a verification trial: @p engine at @p resolution, on @p threads threads.
inline LocalizerOptions trialOptions(Engine engine, int resolution = 64, int threads = 1)
{
  LocalizerOptions options;
  options.engine = engine;
  options.resolution = resolution;
  options.threads = threads;
  return options;
}

/// One localizer with trialOptions() per map of @p maps.
inline std::vector<std::unique_ptr<Localizer>> localizersFor(
    const std::vector<std::shared_ptr<const MapRayCaster>>& maps, Engine engine, int resolution = 64, int threads = 1)
{
  std::vector<std::unique_ptr<Localizer>> localizers;
  for (const auto& map : maps)
  {
    localizers.push_back(std::make_unique<Localizer>(map, trialOptions(engine, resolution, threads)));
  }
  return localizers;
}

/// localizersFor() the maps of smallMaps().
inline std::vector<std::unique_ptr<Localizer>> smallMapLocalizers(Engine engine)
{
  return localizersFor(smallMaps(), engine);
}

inline std::vector<Pose2> trialOffsets(int geometry, int k, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> angle(-kPi, kPi);
  std::vector<Pose2> offsets;
  const Pose2 mounts[4] = { Pose2(0.15, 0.0, 0.0), Pose2(0.0, 0.15, 0.5 * kPi), Pose2(-0.15, 0.0, kPi),
                            Pose2(0.0, -0.15, -0.5 * kPi) };
  for (int i = 0; i < k; ++i)
  {
    if (geometry == kDriving)
    {
      offsets.push_back(compose(Pose2(0.01 * i, 0.0, 0.0), mounts[i % 4]));
    }
    else
    {
      offsets.emplace_back(0.0, 0.0, geometry == kRandom ? angle(rng) : wrapAngle(kTwoPi * i / k));
    }
  }
  return offsets;
}

/// A truth whose every sensor position is in free space; for kGrazing its heading aims the
/// first ray within 0.05 deg of a visible map vertex.
inline Pose2 trialTruth(const MapRayCaster& map, int geometry, const std::vector<Pose2>& offsets, std::mt19937_64& rng)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (;;)
  {
    Pose2 truth = test::randomFreePose(map, rng, 0.1);
    if (geometry == kGrazing)
    {
      std::vector<Vec2> vertices;
      for (const Ring& ring : map.map().rings())
      {
        vertices.insert(vertices.end(), ring.begin(), ring.end());
      }
      const Vec2 v = vertices[static_cast<std::size_t>(unit(rng) * vertices.size()) % vertices.size()];
      const Vec2 d = v - truth.position();
      truth.theta = wrapAngle(std::atan2(d.y(), d.x()) + (unit(rng) - 0.5) * 0.1 * kDeg);
      if (std::abs(map.range(truth) - d.norm()) > 0.05 && map.range(truth) < d.norm())
      {
        continue;  // the vertex is hidden
      }
    }
    bool clear = true;
    for (const Pose2& g : offsets)
    {
      const Vec2 p = compose(truth, g).position();
      clear = clear && map.isFree(p) && test::clearance2(map, p) > 0.01 * 0.01;
    }
    if (clear)
    {
      return truth;
    }
  }
}

/// What the random trials draw from: readings per trial uniformly in [k_min, k_max], and the
/// sensors' cone (0: rays).
struct TrialSpec
{
  int k_min = 4;
  int k_max = 30;
  double half_angle = 0.0;  ///< half the sensors' field of view [rad] (Reading::half_angle)
};

/// A random trial on one of @p maps: geometry, noise, k and the truth, as @p spec says. The
/// random draws do not depend on the cone, so a seed's trials are the same poses with cones.
inline Trial makeTrial(const std::vector<std::shared_ptr<const MapRayCaster>>& maps, std::mt19937_64& rng,
                       const TrialSpec& spec = TrialSpec())
{
  std::uniform_int_distribution<int> pick_map(0, static_cast<int>(maps.size()) - 1), pick_geometry(0, kGeometries - 1),
      pick_k(spec.k_min, spec.k_max);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.005);
  Trial trial;
  trial.map = pick_map(rng);
  trial.geometry = pick_geometry(rng);
  trial.noisy = unit(rng) < 0.5;
  const MapRayCaster& map = *maps[static_cast<std::size_t>(trial.map)];
  const std::vector<Pose2> offsets = trialOffsets(trial.geometry, pick_k(rng), rng);
  trial.truth = trialTruth(map, trial.geometry, offsets, rng);
  trial.readings = test::exactReadings(map, trial.truth, offsets);
  const double max_range = trial.geometry == kNoReturn ? 1.0 + 1.5 * unit(rng) : kInf;
  for (Reading& r : trial.readings)
  {
    r.half_angle = spec.half_angle;
    r.range = spec.half_angle > 0.0 ? coneRange(map, compose(trial.truth, r.offset), spec.half_angle) : r.range;
    r.range = trial.noisy ? std::max(0.0, r.range + noise(rng)) : r.range;
    r.max_range = max_range;
    r.range = r.range > max_range ? kInf : r.range;
  }
  return trial;
}

/// What reproduces a trial: map, geometry, k, truth, and the max range (no-return) or the
/// headings (random directions) that the truth alone does not give.
inline std::string trialLabel(const Trial& trial, int k)
{
  // 17 significant digits: every double prints as itself, so the replay is bit-exact.
  char text[200];
  std::snprintf(text, sizeof(text), "%s map %d k %d %s truth (%.17g, %.17g, %.17g)", geometryName(trial.geometry),
                trial.map, k, trial.noisy ? "noisy" : "exact", trial.truth.x, trial.truth.y, trial.truth.theta);
  std::string label = text;
  if (!trial.readings.empty() && trial.readings.front().half_angle > 0.0)
  {
    std::snprintf(text, sizeof(text), " half angle %.17g", trial.readings.front().half_angle);
    label += text;
  }
  if (trial.geometry == kNoReturn && !trial.readings.empty())
  {
    std::snprintf(text, sizeof(text), " max range %.17g", trial.readings.front().max_range);
    label += text;
  }
  if (trial.geometry == kRandom)
  {
    label += " headings";
    for (const Reading& r : trial.readings)
    {
      std::snprintf(text, sizeof(text), " %.17g", r.offset.theta);
      label += text;
    }
  }
  return label;
}

}  // namespace verification
}  // namespace core
}  // namespace fdml_localization
