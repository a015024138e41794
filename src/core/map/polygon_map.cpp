#include "fdml_localization/core/map/polygon_map.h"

#include <algorithm>
#include <cstring>
#include <sstream>

namespace fdml_localization
{
namespace core
{
namespace
{
std::string formatMessage(const std::string& file, int line, const std::string& reason)
{
  std::ostringstream os;
  os << file;
  if (line > 0)
  {
    os << ":" << line;
  }
  os << ": " << reason;
  return os.str();
}

Ring oriented(const Ring& ring, bool counter_clockwise)
{
  Ring out = ring;
  if ((signedArea(out) > 0.0) != counter_clockwise)
  {
    std::reverse(out.begin(), out.end());
  }
  return out;
}

}  // namespace

MapError::MapError(const std::string& file, int line, const std::string& reason)
  : std::runtime_error(formatMessage(file, line, reason)), file_(file), line_(line), reason_(reason)
{}

Ring cleanRing(const Ring& ring, std::vector<std::size_t>* kept)
{
  Ring out;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < ring.size(); ++i)
  {
    if (!out.empty() && (ring[i] - out.back()).norm() < 1e-12)
    {
      continue;
    }
    out.push_back(ring[i]);
    index.push_back(i);
  }
  while (out.size() > 1 && (out.back() - out.front()).norm() < 1e-12)
  {
    out.pop_back();
    index.pop_back();
  }
  if (kept != nullptr)
  {
    *kept = std::move(index);
  }
  return out;
}

PolygonMap PolygonMap::fromRings(std::vector<Ring> rings, const std::string& source)
{
  const std::vector<RingIssue> issues = validateRings(rings);
  if (!issues.empty())
  {
    const RingIssue& first = issues.front();
    throw MapError(source, 0,
                   "ring " + std::to_string(first.ring + 1) + " vertex " + std::to_string(first.vertex + 1) + ": " +
                       first.reason);
  }
  PolygonMap map;
  for (std::size_t r = 0; r < rings.size(); ++r)
  {
    map.rings_.push_back(oriented(cleanRing(rings[r]), r == 0));
  }
  for (const Ring& ring : map.rings_)
  {
    for (std::size_t i = 0; i < ring.size(); ++i)
    {
      map.edges_.push_back(Segment{ ring[i], ring[(i + 1) % ring.size()] });
      map.bounds_.extend(ring[i]);
    }
    map.area_ += signedArea(ring);  // holes are clockwise: they subtract
  }
  return map;
}

bool PolygonMap::containsBruteForce(const Vec2& p) const
{
  if (rings_.empty() || !pointInRing(p, rings_.front()))
  {
    return false;
  }
  return std::none_of(rings_.begin() + 1, rings_.end(), [&p](const Ring& hole) { return pointInRing(p, hole); });
}

PolygonMap PolygonMap::scaled(double factor) const
{
  std::vector<Ring> rings = rings_;
  for (Ring& ring : rings)
  {
    for (Vec2& v : ring)
    {
      v *= factor;
    }
  }
  return fromRings(std::move(rings), "<scaled map>");
}

std::uint64_t PolygonMap::hash() const
{
  // FNV-1a over ring sizes and the bit patterns of the coordinates.
  std::uint64_t h = 1469598103934665603ULL;
  auto mix = [&h](std::uint64_t value) {
    for (int i = 0; i < 8; ++i)
    {
      h ^= (value >> (8 * i)) & 0xffULL;
      h *= 1099511628211ULL;
    }
  };
  for (const Ring& ring : rings_)
  {
    mix(ring.size());
    for (const Vec2& v : ring)
    {
      for (int axis = 0; axis < 2; ++axis)
      {
        std::uint64_t bits;
        const double value = v[axis] == 0.0 ? 0.0 : v[axis];  // fold -0 into +0
        std::memcpy(&bits, &value, sizeof(bits));
        mix(bits);
      }
    }
  }
  return h;
}

}  // namespace core
}  // namespace fdml_localization
