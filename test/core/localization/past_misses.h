// Replaying a `verify_localization` FAIL line (issue 16): the noise-free trial its label names,
// and the check every past miss must now pass (test_verification_misses.cpp,
// test_generated_map_misses.cpp).
#pragma once

#include "generated_maps.h"
#include "verification_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <sstream>
#include <utility>

namespace fdml_localization
{
namespace core
{
namespace verification
{
/// The trial a FAIL line's label (trialLabel()) describes, noise-free (cones where it names a half angle).
inline Trial trialFrom(std::string label, const std::vector<std::shared_ptr<const MapRayCaster>>& maps)
{
  std::replace_if(
      label.begin(), label.end(), [](char c) { return c == '(' || c == ')' || c == ','; }, ' ');
  std::istringstream in(label);
  std::string geometry, word;
  int k = 0;
  Trial trial;
  in >> geometry >> word >> trial.map >> word >> k >> word >> word >> trial.truth.x >> trial.truth.y >>
      trial.truth.theta;
  for (int g = 0; g < kGeometries; ++g)
  {
    trial.geometry = geometry == geometryName(g) ? g : trial.geometry;
  }
  double max_range = kInf, half_angle = 0.0;
  std::vector<double> headings;
  while (in >> word)
  {
    if (word == "range")
    {
      in >> max_range;
    }
    if (word == "angle")
    {
      in >> half_angle;
    }
    for (double h = 0.0; word == "headings" && in >> h;)
    {
      headings.push_back(h);
    }
  }
  std::mt19937_64 rng(0);
  std::vector<Pose2> offsets = trialOffsets(trial.geometry == kRandom ? kTurning : trial.geometry, k, rng);
  for (std::size_t i = 0; i < headings.size() && i < offsets.size(); ++i)
  {
    offsets[i] = Pose2(0.0, 0.0, headings[i]);
  }
  const MapRayCaster& map = *maps[static_cast<std::size_t>(trial.map)];
  trial.readings = test::exactReadings(map, trial.truth, offsets);
  for (Reading& r : trial.readings)
  {
    r.half_angle = half_angle;
    r.range = half_angle > 0.0 ? coneRange(map, compose(trial.truth, r.offset), half_angle) : r.range;
    r.max_range = max_range;
    r.range = r.range > max_range ? kInf : r.range;
  }
  return trial;
}

/// The noise-free trial of @p label on @p maps, localized by @p engine at @p resolution: every
/// failure of checkNoiseFree() (the truth missed, the best candidate inaccurate) added.
inline void expectTruthFound(const std::vector<std::shared_ptr<const MapRayCaster>>& maps, const std::string& label,
                             Engine engine, int resolution)
{
  const Trial trial = trialFrom(label, maps);
  Localizer localizer(maps[static_cast<std::size_t>(trial.map)], trialOptions(engine, resolution));
  Figures figures;
  checkNoiseFree(localizer, trial, localizer.localize(trial.readings), label, figures);
  for (const std::string& failure : figures.failures)
  {
    ADD_FAILURE() << toString(engine) << ", resolution " << resolution << ": " << failure;
  }
}

/// expectTruthFound() for both engines at resolution 64 on the maps
/// generatedMaps(@p random_maps, @p buildings, @p seed, @p rooms) draws (verify_localization's).
inline void expectTruthFoundOnGeneratedMaps(int random_maps, int buildings, std::uint64_t seed,
                                            const std::string& label, int rooms = 0)
{
  std::vector<std::shared_ptr<const MapRayCaster>> maps;
  for (GeneratedMap& generated : generatedMaps(random_maps, buildings, seed, rooms))
  {
    maps.push_back(std::move(generated.map));
  }
  for (const Engine engine : { Engine::Voxel, Engine::Adaptive })
  {
    expectTruthFound(maps, label, engine, 64);
  }
}

}  // namespace verification
}  // namespace core
}  // namespace fdml_localization
