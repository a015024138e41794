/**
 * @file scenario_readers.h
 * @brief Readers of scenario sections shared by the scenario parser's files (scenario.cpp,
 *        scenario_readers.cpp); see parseScenario() in scenario.h for the format.
 */
#pragma once

#include "fdml_localization/simulation/scenario.h"

namespace fdml_localization
{
namespace core
{
/// Largest coordinate a scenario may give [m].
constexpr double kMaxScenarioCoordinate = 1e5;

/// Reads the list of [x, y] points [m] under @p key (absent: empty), reporting bad items.
std::vector<Vec2> readPoints(FieldReader* parent, const std::string& key, std::vector<std::string>* errors);

/// Reads the `obstacles` list of groups under @p root, reporting every problem by its key path.
void readObstacles(FieldReader* root, std::vector<ObstacleGroupConfig>* groups, std::vector<std::string>* errors);

}  // namespace core
}  // namespace fdml_localization
