/**
 * @file cell_geometry.h
 * @brief Small exact 2D helpers of the conservative cell bounds (cell_bounds.h): half-planes,
 *        convex clipping, convex hulls and segment-box distances.
 */
#pragma once

#include "fdml_localization/core/geometry/geometry.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/// The closed half-plane {x : normal . x <= offset}.
struct HalfPlane
{
  Vec2 normal;
  double offset = 0.0;
};

/// The part of the convex polygon @p poly (any orientation) inside @p h (Sutherland-Hodgman).
std::vector<Vec2> clipPolygon(const std::vector<Vec2>& poly, const HalfPlane& h);

/// Clips the segment [a, b] to the intersection of @p planes; false when nothing is left.
bool clipSegment(Vec2& a, Vec2& b, const std::vector<HalfPlane>& planes);

/// Convex hull of @p points (reordered) into @p hull, counter-clockwise, without collinear points
/// (Andrew's monotone chain).
void convexHull(std::vector<Vec2>& points, std::vector<Vec2>& hull);

/// The half-planes whose intersection is the counter-clockwise convex polygon @p hull (>= 3 points).
void hullHalfPlanes(const std::vector<Vec2>& hull, std::vector<HalfPlane>& planes);

/// Distance between the segment [a, b] and the closed box (0 when they meet) [m].
double segmentBoxDistance(const Vec2& a, const Vec2& b, const Box2& box);

/// True when the segment [a, b] meets the closed box.
bool segmentTouchesBox(const Vec2& a, const Vec2& b, const Box2& box);

}  // namespace core
}  // namespace fdml_localization
