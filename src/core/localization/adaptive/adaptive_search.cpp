#include "fdml_localization/core/localization/adaptive/adaptive_search.h"

#include "fdml_localization/core/geometry/cone_cast.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fdml_localization
{
namespace core
{
namespace
{
/// True when a box that meets no map edge lies outside free space (test its centre).
bool outsideFreeSpace(const MapRayCaster& map, const Box2& box)
{
  return !map.grid().anySegmentInBox(box) && !map.isFree(0.5 * (box.min + box.max));
}

Box2 sweep(const Box2& positions, const Box2& arc, double inflate)
{
  Box2 out;
  out.min = positions.min + arc.min - Vec2(inflate, inflate);
  out.max = positions.max + arc.max + Vec2(inflate, inflate);
  return out;
}

/**
 * True when one map edge stops every ray from every point of @p sensors in every heading of
 * [a0, a1] [rad] nearer than @p reach [m]: the edge the centre's middle ray hits, with every
 * corner of @p sensors strictly on the same side of its line, seeing both extreme headings
 * within the edge's angular span, and at most @p reach from both its ends. Over a box, the
 * direction to a fixed point is extreme at a corner (it turns monotonically along each side)
 * and so is the distance to it; a ray that meets another edge first stops even nearer.
 */
bool oneEdgeStopsEveryRay(const MapRayCaster& map, const Box2& sensors, double a0, double a1, double reach)
{
  if (!(a1 - a0 < kPi) || !(reach > 0.0))
  {
    return false;
  }
  const double mid = 0.5 * (a0 + a1);
  const RayHit hit = map.cast(0.5 * (sensors.min + sensors.max), Vec2(std::cos(mid), std::sin(mid)));
  if (!hit.hit() || !(hit.distance < reach))
  {
    return false;
  }
  const Segment& edge = map.grid().segments()[static_cast<std::size_t>(hit.segment)];
  const Vec2 u0(std::cos(a0), std::sin(a0));
  const Vec2 u1(std::cos(a1), std::sin(a1));
  const Vec2 corners[4] = { sensors.min, Vec2(sensors.max.x(), sensors.min.y()), sensors.max,
                            Vec2(sensors.min.x(), sensors.max.y()) };
  int side = 0;
  for (const Vec2& c : corners)
  {
    const Vec2 da = edge.a - c;
    const Vec2 db = edge.b - c;
    const double turn = cross(da, db);
    const int s = turn > 1e-12 ? 1 : (turn < -1e-12 ? -1 : 0);
    if (s == 0 || (side != 0 && s != side) || std::max(da.norm(), db.norm()) >= reach)
    {
      return false;
    }
    side = s;
    const Vec2& first = s > 0 ? da : db;  // the span runs counterclockwise from first to last
    const Vec2& last = s > 0 ? db : da;
    if (cross(first, u0) < 0.0 || cross(u0, last) < 0.0 || cross(first, u1) < 0.0 || cross(u1, last) < 0.0)
    {
      return false;
    }
  }
  return true;
}

/**
 * True when every pose of @p box sees a map edge point inside its cone nearer than @p limit [m], so
 * that no pose explains @p reading (a cone, half_angle > 0). The headings every pose's cone covers
 * form a window of width 2 a - (t1 - t0); the sensor lies within rho of the centre's sensor c. A
 * point q at least r_min = rho / sin(w / 4) from c is seen from every sensor position within w / 4
 * of its direction from c, so one inside the centre's sector of half-angle w / 4 (the window less
 * that slack on each side) lies in every pose's cone, and at most |q - c| + rho from its sensor.
 */
bool coneCertainlyNearer(const MapRayCaster& map, const Reading& reading, const PoseBox& box, double limit)
{
  const double window = 2.0 * std::min(reading.half_angle, kMaxConeHalfAngle) - (box.t1 - box.t0);
  if (!(window > 0.0))
  {
    return false;
  }
  const Vec2 g(reading.offset.x, reading.offset.y);
  const double rho = 0.5 * std::hypot(box.x1 - box.x0, box.y1 - box.y0) + 0.5 * g.norm() * (box.t1 - box.t0);
  const double slack = 0.25 * window;
  const double r_min = rho / std::sin(slack);
  const double reach = (limit - rho) * (1.0 - 1e-12);
  if (!(r_min < reach))
  {
    return false;
  }
  const Pose2 centre(0.5 * (box.x0 + box.x1), 0.5 * (box.y0 + box.y1), 0.5 * (box.t0 + box.t1));
  const double nearest = coneRange(map, compose(centre, reading.offset), 0.5 * window - slack, reach);
  return nearest >= r_min && nearest < reach;
}

/// True when every pose of @p box has a map edge point in its reading's cone (its ray) nearer
/// than @p limit [m]: one edge stops every ray along the axis (a cone's range is no longer), or, for
/// a cone, coneCertainlyNearer().
bool nearerEverywhere(const MapRayCaster& map, const Reading& reading, const PoseBox& box, const Box2& sensors,
                      double limit)
{
  const double t0 = box.t0 + reading.offset.theta;
  const double t1 = box.t1 + reading.offset.theta;
  return oneEdgeStopsEveryRay(map, sensors, t0, t1, limit) ||
         (reading.half_angle > 0.0 && coneCertainlyNearer(map, reading, box, limit));
}

/// readingMayExplain() with the reading's arcs over the box's headings: @p sensor_arc, the
/// rotatedArcBounds() of its sensor's offset, and @p hit_arc, its hitArcBounds().
bool mayExplainWithin(const MapRayCaster& map, const Reading& reading, const PoseBox& box, const Box2& sensor_arc,
                      const Box2& hit_arc, double range_tolerance)
{
  Box2 positions;
  positions.extend(Vec2(box.x0, box.y0));
  positions.extend(Vec2(box.x1, box.y1));
  const Pose2& g = reading.offset;
  const Box2 sensors = sweep(positions, sensor_arc, 0.0);
  // The sensor must be in free space somewhere in the box (for a sensor at the base origin the
  // caller's robot-position test already says so).
  if ((g.x != 0.0 || g.y != 0.0) && outsideFreeSpace(map, sensors))
  {
    return false;
  }
  if (!std::isfinite(reading.range))
  {
    // A no-return reading agrees when nothing is nearer than max_range - tau.
    return !nearerEverywhere(map, reading, box, sensors, reading.max_range - range_tolerance);
  }
  // Some edge point where the reading ends, and not something nearer for every pose.
  return map.grid().anySegmentInBox(sweep(positions, hit_arc, range_tolerance)) &&
         !nearerEverywhere(map, reading, box, sensors, reading.range - range_tolerance);
}
}  // namespace

Box2 rotatedArcBounds(const Vec2& v, double t0, double t1)
{
  Box2 box;
  const double r = v.norm();
  if (r == 0.0)
  {
    box.extend(Vec2::Zero());
    return box;
  }
  const double phi = std::atan2(v.y(), v.x());
  const double a0 = t0 + phi;
  const double a1 = t1 + phi;
  box.extend(Vec2(r * std::cos(a0), r * std::sin(a0)));
  box.extend(Vec2(r * std::cos(a1), r * std::sin(a1)));
  // Axis extremes at multiples of pi/2 inside [a0, a1].
  for (double k = std::ceil(a0 / (0.5 * kPi)); k * 0.5 * kPi <= a1; k += 1.0)
  {
    const double a = k * 0.5 * kPi;
    box.extend(Vec2(r * std::cos(a), r * std::sin(a)));
  }
  return box;
}

Box2 hitArcBounds(const Reading& reading, double t0, double t1)
{
  if (!std::isfinite(reading.range))
  {
    return Box2();
  }
  const Pose2& g = reading.offset;
  const Vec2 direction(reading.range * std::cos(g.theta), reading.range * std::sin(g.theta));
  if (reading.half_angle <= 0.0)
  {
    return rotatedArcBounds(Vec2(g.x, g.y) + direction, t0, t1);
  }
  const Box2 sensor = rotatedArcBounds(Vec2(g.x, g.y), t0, t1);
  const Box2 ray = rotatedArcBounds(direction, t0 - reading.half_angle, t1 + reading.half_angle);
  Box2 out;
  out.min = sensor.min + ray.min;
  out.max = sensor.max + ray.max;
  return out;
}

bool readingMayExplain(const MapRayCaster& map, const Reading& reading, const PoseBox& box, double range_tolerance)
{
  const Pose2& g = reading.offset;
  return mayExplainWithin(map, reading, box, rotatedArcBounds(Vec2(g.x, g.y), box.t0, box.t1),
                          hitArcBounds(reading, box.t0, box.t1), range_tolerance);
}

int boxConsensusBound(const MapRayCaster& map, const std::vector<Reading>& readings, double range_tolerance,
                      const PoseBox& box, int needed)
{
  return BoxConsensusTest(map, readings, range_tolerance).bound(box, needed);
}

BoxConsensusTest::BoxConsensusTest(const MapRayCaster& map, const std::vector<Reading>& readings,
                                   double range_tolerance)
  : map_(map)
  , readings_(readings)
  , range_tolerance_(range_tolerance)
  , order_(readings.size())
  , sensor_arcs_(readings.size())
  , hit_arcs_(readings.size())
  , have_arcs_(readings.size(), 0)
{
  std::iota(order_.begin(), order_.end(), std::size_t{ 0 });
}

int BoxConsensusTest::bound(const PoseBox& box, int needed)
{
  if (outsideFreeSpace(map_, Box2{ Vec2(box.x0, box.y0), Vec2(box.x1, box.y1) }))
  {
    return 0;
  }
  int count = 0;
  const std::size_t k = order_.size();
  for (std::size_t i = 0; i < k && count + static_cast<long>(k - i) >= needed; ++i)
  {
    const std::size_t r = order_[i];
    ensureArcs(r, box);
    if (mayExplainWithin(map_, readings_[r], box, sensor_arcs_[r], hit_arcs_[r], range_tolerance_))
    {
      ++count;
    }
    else
    {
      // The next box, nearby, is mostly ruled out by the same reading: it goes first. The ones
      // tested before it move up by one, so none is tested twice.
      std::rotate(order_.begin(), order_.begin() + static_cast<std::ptrdiff_t>(i),
                  order_.begin() + static_cast<std::ptrdiff_t>(i + 1));
    }
  }
  return count;
}

void BoxConsensusTest::ensureArcs(std::size_t r, const PoseBox& box)
{
  if (box.t0 != arcs_t0_ || box.t1 != arcs_t1_)
  {
    arcs_t0_ = box.t0;
    arcs_t1_ = box.t1;
    std::fill(have_arcs_.begin(), have_arcs_.end(), 0);
  }
  if (!have_arcs_[r])
  {
    const Pose2& g = readings_[r].offset;
    sensor_arcs_[r] = rotatedArcBounds(Vec2(g.x, g.y), box.t0, box.t1);
    hit_arcs_[r] = hitArcBounds(readings_[r], box.t0, box.t1);
    have_arcs_[r] = 1;
  }
}

AdaptiveSearchResult adaptiveSearch(const MapRayCaster& map, const std::vector<Reading>& readings,
                                    const AdaptiveSearchOptions& options)
{
  const BoxOccupancy occupancy(map, options.cell_xy);
  return adaptiveSearch(map, occupancy, readings, options);
}

AdaptiveSearchResult adaptiveSearch(const MapRayCaster& map, const BoxOccupancy& occupancy,
                                    const std::vector<Reading>& readings, const AdaptiveSearchOptions& options)
{
  AdaptiveSearchOptions o = options;
  o.floor_count = options.min_count;
  AdaptiveSearch search(map, occupancy, readings, o);
  return search.run(options.min_count);
}

}  // namespace core
}  // namespace fdml_localization
