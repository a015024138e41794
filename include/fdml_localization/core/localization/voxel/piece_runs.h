/**
 * @file piece_runs.h
 * @brief Internals of pieceBound() (cell_bounds.h): runs of map edges hit by the rays of a
 *        piece's vertices, and the tests that every ray of the piece crosses one ahead of it.
 */
#pragma once

#include "fdml_localization/core/localization/voxel/cell_bounds.h"
#include "fdml_localization/core/localization/voxel/cell_geometry.h"

#include <utility>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace piece
{
inline constexpr int kMaxGap = 3;       ///< hit edges at most this far apart along a ring share a run
inline constexpr int kMaxRunEdges = 8;  ///< longer runs fall back
inline constexpr int kMaxRuns = 4;
inline constexpr int kMaxChains = 8;
inline constexpr double kAhead = 1e-9;  ///< [m] strictness of the "ahead" tests
inline constexpr double kWiden = 1e-7;  ///< [m] margin of the wedge the runs are extended over
/// A connected chain of map edges: edges first..first+count-1 of a ring (cyclic) and its points.
struct Run
{
  int ring = 0;
  int first = 0;  ///< position in the ring
  int count = 0;
  std::size_t begin = 0;  ///< its points: Scratch::points[begin, end)
  std::size_t end = 0;
};

/// Per-thread buffers (the bound runs once per cell: no allocation in the steady state).
struct Scratch
{
  std::vector<std::pair<int, double>> params;
  std::vector<int> edges;
  std::vector<int> positions;
  std::vector<Run> runs;
  std::vector<Vec2> points;
  std::vector<Vec2> hull_points;
  std::vector<Vec2> hull;
  std::vector<HalfPlane> planes;
  std::vector<HalfPlane> wedge;  ///< superset of the piece's rays beyond its own extent
  std::vector<HalfPlane> ahead;  ///< strictly ahead of every vertex of the piece at t0 and t1
  std::vector<Vec2> chain_points;
  std::vector<Run> chains;
};

struct Frame
{
  const MapRayCaster& map;
  const EdgeRings& rings;
  const std::vector<Vec2>& piece;
  Vec2 u[2];
  Scratch& scratch;
};

/// The points of a run.
struct RunPoints
{
  const Vec2* b;
  const Vec2* e;
  const Vec2* begin() const
  {
    return b;
  }
  const Vec2* end() const
  {
    return e;
  }
};

inline RunPoints pointsOf(const Frame& f, const Run& run)
{
  return RunPoints{ f.scratch.points.data() + run.begin, f.scratch.points.data() + run.end };
}
/// Edge at @p position (cyclic) of @p ring.
int edgeAt(const EdgeRings& rings, int ring, int position);
/// Runs of scratch.edges into scratch.runs: per ring, split where the cyclic gap exceeds kMaxGap;
/// false when there are too many runs or one is too long.
bool groupRuns(const EdgeRings& rings, Scratch& scratch);
/// Fills the run's points: the hits' extreme points on its end edges, extended over the part of
/// the end edges inside the wedge, and its inner vertices.
void runPoints(const Frame& f, Run& run);
/// Every ray of the piece that meets the run's line meets it ahead of its origin.
bool runAhead(const Frame& f, const Run& run);
/// Splits the runs into chains whose every segment lies ahead, clipping the others to the region
/// ahead of the piece; the chains replace the runs (their points in scratch.points).
void splitAhead(const Frame& f, std::vector<Run>& runs);
/// Some chain point lies on the right of every ray of the cell and some on the left.
bool bracketsEveryRay(const Frame& f, const std::vector<Run>& chains);
/// The runs' lateral extents form one interval for every ray of the piece (sufficient test).
bool runsConnected(const Frame& f, const std::vector<Run>& runs);

}  // namespace piece
}  // namespace core
}  // namespace fdml_localization
