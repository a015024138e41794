// Readers of the scenario's point lists and obstacle groups (scenario_readers.h); the other
// sections are read in scenario.cpp.
#include "fdml_localization/simulation/scenario_readers.h"

#include <cmath>
#include <limits>

namespace fdml_localization
{
namespace core
{
/// Reads a list of [x, y] points.
std::vector<Vec2> readPoints(FieldReader* parent, const std::string& key, std::vector<std::string>* errors)
{
  std::vector<Vec2> points;
  const ParamValue* node = parent->child(key);
  if (node == nullptr)
  {
    return points;
  }
  const std::string path = parent->pathOf(key);
  if (!node->isList())
  {
    errors->push_back(path + ": must be a list of [x, y] points, got " + ParamValue::typeName(node->type()));
    return points;
  }
  for (std::size_t i = 0; i < node->items().size(); ++i)
  {
    const ParamValue& item = node->items()[i];
    const std::string item_path = path + "[" + std::to_string(i) + "]";
    if (!item.isList() || item.items().size() != 2 || !item.items()[0].isNumber() || !item.items()[1].isNumber())
    {
      errors->push_back(item_path + ": must be a point [x, y] of two numbers");
      continue;
    }
    const Vec2 p(item.items()[0].asDouble(), item.items()[1].asDouble());
    if (!p.allFinite() || p.cwiseAbs().maxCoeff() > kMaxScenarioCoordinate)
    {
      errors->push_back(item_path + ": coordinates must be finite and within 1e5 m");
      continue;
    }
    points.push_back(p);
  }
  return points;
}

namespace
{
/// An obstacle group's count, shape, radius and vertices.
void readObstacleShape(FieldReader& r, ObstacleGroupConfig* g, std::vector<std::string>* errors)
{
  std::int64_t count = g->count;
  if (r.integer("count", &count, 0, 10000))
  {
    g->count = static_cast<int>(count);
  }
  std::string shape = "disc";
  r.string("shape", &shape, false, { "disc", "polygon" });
  g->polygon = shape == "polygon";
  r.number("radius", &g->radius, 1e-3, 100.0);
  g->vertices = readPoints(&r, "vertices", errors);
  if (g->polygon && (g->vertices.size() < 3 || std::abs(signedArea(g->vertices)) < 1e-9))
  {
    r.error("vertices", "a polygon obstacle needs at least 3 vertices enclosing a positive area");
  }
  if (!g->polygon && !g->vertices.empty())
  {
    r.error("vertices", "only allowed with shape 'polygon'");
  }
}

/// An obstacle group's motion, speed, waypoints, start positions and seed.
void readObstacleMotion(FieldReader& r, ObstacleGroupConfig* g, std::vector<std::string>* errors)
{
  std::string motion = "static";
  if (r.string("motion", &motion, false, { "static", "bounce", "waypoints", "random_walk" }))
  {
    g->motion = motion == "static"    ? ObstacleMotion::Static :
                motion == "bounce"    ? ObstacleMotion::Bounce :
                motion == "waypoints" ? ObstacleMotion::Waypoints :
                                        ObstacleMotion::RandomWalk;
  }
  r.number("speed", &g->speed, 0.0, 20.0);
  r.number("turn_sigma", &g->turn_sigma, 0.0, 100.0);
  g->waypoints = readPoints(&r, "waypoints", errors);
  g->positions = readPoints(&r, "positions", errors);
  std::int64_t seed = 0;
  if (r.integer("seed", &seed, 0, std::numeric_limits<std::int64_t>::max()))
  {
    g->seed = static_cast<std::uint64_t>(seed);
  }
  if (g->motion == ObstacleMotion::Waypoints && g->waypoints.size() < 2)
  {
    r.error("waypoints", "motion 'waypoints' needs at least 2 waypoints");
  }
  if (g->motion != ObstacleMotion::Waypoints && !g->waypoints.empty())
  {
    r.error("waypoints", "only allowed with motion 'waypoints'");
  }
  if (!g->positions.empty() && static_cast<int>(g->positions.size()) != g->count)
  {
    r.error("positions",
            "has " + std::to_string(g->positions.size()) + " points but count is " + std::to_string(g->count));
  }
}

}  // namespace

void readObstacles(FieldReader* root, std::vector<ObstacleGroupConfig>* groups, std::vector<std::string>* errors)
{
  const ParamValue* node = root->child("obstacles");
  if (node == nullptr)
  {
    return;
  }
  if (!node->isList())
  {
    root->error("obstacles",
                std::string("must be a list of obstacle groups, got ") + ParamValue::typeName(node->type()));
    return;
  }
  for (std::size_t i = 0; i < node->items().size(); ++i)
  {
    ObstacleGroupConfig g;
    FieldReader r(node->items()[i], root->pathOf("obstacles") + "[" + std::to_string(i) + "]", errors);
    readObstacleShape(r, &g, errors);
    readObstacleMotion(r, &g, errors);
    r.finish();
    groups->push_back(g);
  }
}

}  // namespace core
}  // namespace fdml_localization
