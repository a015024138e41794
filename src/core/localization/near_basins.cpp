// settleInNearBasins() (robust_search.h): the candidates' last polish, escapes leaving out pairs
// of directions, then a fine lattice around them, where a ray passing a vertex splits the cost into
// basins a centimetre wide.
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/region_starts.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/seed_refiner.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <vector>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Lattice rounds of settleInNearBasins() around a candidate, each around the better pose found.
constexpr int kNearBasinRounds = 3;
/// The lattice around an exact candidate (absorbExactTwins()) is this many steps wide.
constexpr double kTwinSteps = 4.0;

/// True when the cost may jump within about a lattice @p step_xy [m], @p step_theta [rad] of
/// @p candidate: a finite inlier's ray passes a vertex within the move of its sensor there
/// (vertexMargins()), or a reading is a cone (its nearest point can jump). Elsewhere the cost is
/// smooth around the candidate and its polish already reached that basin's least residual.
bool nearAnEdge(const MapRayCaster& map, const std::vector<Reading>& readings, const Candidate& candidate,
                double step_xy, double step_theta)
{
  const std::vector<double> margins = vertexMargins(map, candidate.pose, readings, step_theta);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const Reading& r = readings[i];
    const double moved = 2.0 * step_xy + r.offset.position().norm() * step_theta;
    if (r.half_angle > 0.0 || (candidate.inlier_mask[i] && margins[i] < moved))
    {
      return true;
    }
  }
  return false;
}

/// The 26 poses of a lattice @p step_xy [m], @p step_theta [rad] around @p q (q itself left out).
std::vector<Pose2> latticeAround(const Pose2& q, double step_xy, double step_theta)
{
  std::vector<Pose2> poses;
  for (int a = -1; a <= 1; ++a)
  {
    for (int b = -1; b <= 1; ++b)
    {
      for (int c = -1; c <= 1; ++c)
      {
        if (a != 0 || b != 0 || c != 0)
        {
          poses.emplace_back(q.x + a * step_xy, q.y + b * step_xy, wrapAngle(q.theta + c * step_theta));
        }
      }
    }
  }
  return poses;
}

/// @p candidate moved to the best pose polished from the 26 poses of a lattice @p step_xy [m],
/// @p step_theta [rad] around it, while that is better and half a step away or more and the
/// candidate is near an edge of the cost (nearAnEdge()), kNearBasinRounds times at most.
void settleInNearBasin(const MapRayCaster& map, const std::vector<Reading>& readings,
                       const RefinementSettings& settings, double step_xy, double step_theta, Candidate& candidate)
{
  for (int round = 0; round < kNearBasinRounds && candidate.rms_residual >= kExactRms &&
                      nearAnEdge(map, readings, candidate, step_xy, step_theta);
       ++round)
  {
    Candidate best = candidate;
    for (const Pose2& start : latticeAround(candidate.pose, step_xy, step_theta))
    {
      Candidate polished = polishedFrom(map, readings, settings, candidate, start);
      if (betterCandidate(polished, best))
      {
        best = std::move(polished);
      }
    }
    if (!betterCandidate(best, candidate))
    {
      return;
    }
    // A move of less than half a step found the same basin again: no new lattice.
    const Eigen::Vector3d d = poseDifference(best.pose, candidate.pose);
    const bool far = d.head<2>().norm() >= 0.5 * step_xy || std::abs(d.z()) >= 0.5 * step_theta;
    best.covariance = candidate.covariance;  // widened along continua, tied duplicates absorbed
    candidate = std::move(best);
    if (!far)
    {
      return;
    }
  }
}

/// Two readings crossing edges between @p candidate (short of exact) and its basin's optimum hold
/// every polish on all of its readings away from it, and leaving out either alone explains fewer:
/// what the escapes reach leaving out pairs of readings too (RefinementSettings::escape_pairs),
/// when that is better, replaces @p candidate within its uniqueness margins and goes to
/// @p elsewhere beyond them (another place, which @p candidate still is). Verification seed 865:
/// driving, the front rays grazed an edge at the exact truth and the right one crossed a corner;
/// the polish stopped 5.2 cm and 1.25 deg from the truth.
void escapeInPairs(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                   const RefinementSettings& settings, Candidate& candidate, std::vector<Candidate>& elsewhere)
{
  if (candidate.rms_residual < kExactRms)
  {
    return;
  }
  RefinementSettings pairs = settings;
  pairs.escape_pairs = true;
  const std::vector<Pose2> none;
  Refiner refiner(map, candidate.pose, readings, candidate.inlier_mask, pairs, none);
  refiner.escapes();
  Candidate escaped = refiner.candidate();
  if (!betterCandidate(escaped, candidate))
  {
    return;
  }
  escaped.support = candidate.support;
  if (!withinMargins(escaped.pose, candidate.pose, options.uniqueness_distance, options.uniqueness_angle))
  {
    widenAlongContinua(map, readings, settings.noise_sigma, escaped);
    elsewhere.push_back(std::move(escaped));
    return;
  }
  escaped.covariance = candidate.covariance;  // widened along continua, tied duplicates absorbed
  candidate = std::move(escaped);
}

/// Widens the covariance of an exact @p candidate near an edge of the cost (nearAnEdge()) to cover the exact places
/// polished from a lattice kTwinSteps steps (@p step_xy [m], @p step_theta [rad]) around it that tie it within the
/// uniqueness margins (absorbTiedDuplicates()): the engine returns one of such twins, and the readings cannot tell
/// which. Rays with 6 readings, mostly no-returns: an exact place 4.8 cm and 2.5 deg from the exact truth, found by
/// both engines while the truth was not (verification seed 815); a cone's edge sweeping a wall steeply: two exact
/// headings 3.1 deg apart at the truth's position (seed 812).
void absorbExactTwins(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                      const RefinementSettings& settings, double step_xy, double step_theta, Candidate& candidate)
{
  if (candidate.rms_residual >= kExactRms || !nearAnEdge(map, readings, candidate, step_xy, step_theta))
  {
    return;
  }
  std::vector<Candidate> twins;
  for (const Pose2& start : latticeAround(candidate.pose, kTwinSteps * step_xy, kTwinSteps * step_theta))
  {
    Candidate twin = polishedFrom(map, readings, settings, candidate, start);
    if (twin.rms_residual < kExactRms)
    {
      twins.push_back(std::move(twin));
    }
  }
  std::vector<Candidate> kept{ candidate };
  absorbTiedDuplicates(twins, options.uniqueness_distance, options.uniqueness_angle, settings.noise_sigma, kept);
  candidate.covariance = kept.front().covariance;
}

}  // namespace

void settleInNearBasins(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                        const RefinementSettings& settings, std::vector<Candidate>& candidates)
{
  if (candidates.empty())
  {
    return;
  }
  const double step_xy = 0.5 * options.range_tolerance;
  const double step_theta = std::min(step_xy / medianFiniteRange(readings), 0.25 * options.uniqueness_angle);
  // Ranked: those tied at the best net consensus come first.
  long tied = 0;
  while (tied < static_cast<long>(candidates.size()) &&
         netConsensus(candidates[static_cast<std::size_t>(tied)]) == netConsensus(candidates.front()))
  {
    ++tied;
  }
  const int threads = options.threads > 0 ? options.threads : omp_get_max_threads();
  std::vector<std::vector<Candidate>> elsewhere(static_cast<std::size_t>(tied));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (tied >= 2)
  for (long j = 0; j < tied; ++j)
  {
    escapeInPairs(map, readings, options, settings, candidates[static_cast<std::size_t>(j)],
                  elsewhere[static_cast<std::size_t>(j)]);
    settleInNearBasin(map, readings, settings, step_xy, step_theta, candidates[static_cast<std::size_t>(j)]);
    absorbExactTwins(map, readings, options, settings, step_xy, step_theta, candidates[static_cast<std::size_t>(j)]);
  }
  for (std::vector<Candidate>& found : elsewhere)
  {
    std::move(found.begin(), found.end(), std::back_inserter(candidates));
  }
  candidates = rankAndDeduplicate(std::move(candidates), options.uniqueness_distance, options.uniqueness_angle,
                                  options.max_candidates);
}

}  // namespace core
}  // namespace fdml_localization
