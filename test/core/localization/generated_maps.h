/**
 * @file generated_maps.h
 * @brief Maps no test was tuned on, drawn from a seed: random star-shaped 70-gons, small
 *        generated buildings and furnished rooms (the verification suite's unseen maps:
 *        verify_localization --random-maps / --buildings / --rooms, and the fast part in
 *        test_verification.cpp).
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"
#include "fdml_localization/core/geometry/ray_caster.h"
#include "fdml_localization/simulation/furnished_room.h"
#include "fdml_localization/simulation/map_generators.h"

#include <cstdint>
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
/// A generated map and what it is.
struct GeneratedMap
{
  std::shared_ptr<const MapRayCaster> map;
  std::string name;
};

/**
 * @brief @p random_maps random star-shaped 70-gons (mean radius 2 m, radii 1 to 3 m), then
 *        @p buildings generated 12 x 9 m buildings (1.2 m corridors, 3 m rooms, 10 cm walls,
 *        80 cm doors), then @p rooms furnished rooms (furnishedRoom(): 20 boxes and pillars of
 *        10 to 60 cm; the even ones 8 x 6 m rectangles, the odd ones round halls 10 m across,
 *        each turned by a random angle); the i-th of each kind drawn with seed @p seed * 1000 + i.
 */
inline std::vector<GeneratedMap> generatedMaps(int random_maps, int buildings, std::uint64_t seed, int rooms = 0)
{
  std::vector<GeneratedMap> maps;
  for (int i = 0; i < random_maps; ++i)
  {
    const std::uint64_t s = seed * 1000 + static_cast<std::uint64_t>(i);
    maps.push_back({ std::make_shared<const MapRayCaster>(randomPolygon(70, 2.0, 0.5, s)),
                     "randomPolygon(70, 2 m, 0.5, seed " + std::to_string(s) + ")" });
  }
  for (int i = 0; i < buildings; ++i)
  {
    BuildingOptions building;
    building.width = 12.0;
    building.height = 9.0;
    building.corridor_width = 1.2;
    building.room_size = 3.0;
    building.wall_thickness = 0.1;
    building.door_width = 0.8;
    building.seed = seed * 1000 + static_cast<std::uint64_t>(i);
    maps.push_back({ std::make_shared<const MapRayCaster>(generateBuilding(building)),
                     "generateBuilding(12 x 9 m, seed " + std::to_string(building.seed) + ")" });
  }
  for (int i = 0; i < rooms; ++i)
  {
    FurnishedRoomOptions room;
    room.seed = seed * 1000 + static_cast<std::uint64_t>(i);
    room.round = i % 2 == 1;
    room.width = room.round ? 10.0 : 8.0;
    std::mt19937_64 rng(room.seed);
    room.rotation = std::uniform_real_distribution<double>(0.0, kPi)(rng);
    maps.push_back({ std::make_shared<const MapRayCaster>(furnishedRoom(room)),
                     std::string("furnishedRoom(") + (room.round ? "round hall 10 m" : "8 x 6 m") + ", rotation " +
                         std::to_string(room.rotation) + " rad, seed " + std::to_string(room.seed) + ")" });
  }
  return maps;
}

}  // namespace verification
}  // namespace core
}  // namespace fdml_localization
