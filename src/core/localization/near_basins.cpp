// settleInNearBasins() (robust_search.h): the candidates' last polish, escapes leaving out pairs
// of directions, then a fine lattice around them, where a ray passing a vertex splits the cost into
// basins a centimetre wide.
#include "fdml_localization/core/localization/ranking.h"
#include "fdml_localization/core/localization/region_starts.h"
#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/seed_refiner.h"

#include "fdml_localization/core/util/threads.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
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

/// Polishes @p candidate from @p starts: the poses reached that tie it (as many readings net, an
/// RMS below @p max_rms) widen its covariance within the uniqueness margins
/// (absorbTiedDuplicates(): the engine returns one of such twins, and the readings cannot tell
/// which) and go to @p elsewhere beyond them, one per place (another place just as good).
void twinsFrom(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
               const RefinementSettings& settings, const std::vector<Pose2>& starts, double max_rms,
               Candidate& candidate, std::vector<Candidate>& elsewhere)
{
  const auto near = [&](const Pose2& a, const Pose2& b) {
    return withinMargins(a, b, options.uniqueness_distance, options.uniqueness_angle);
  };
  std::vector<Candidate> twins;
  for (const Pose2& start : starts)
  {
    Candidate twin = polishedFrom(map, readings, settings, candidate, start);
    if (netConsensus(twin) < netConsensus(candidate) || !(twin.rms_residual < max_rms))
    {
      continue;
    }
    if (near(twin.pose, candidate.pose))
    {
      twins.push_back(std::move(twin));
    }
    else if (std::none_of(elsewhere.begin(), elsewhere.end(),
                          [&](const Candidate& c) { return near(c.pose, twin.pose); }))
    {
      widenAlongContinua(map, readings, settings.noise_sigma, twin);
      elsewhere.push_back(std::move(twin));
    }
  }
  std::vector<Candidate> kept{ candidate };
  absorbTiedDuplicates(twins, options.uniqueness_distance, options.uniqueness_angle, settings.noise_sigma, kept);
  candidate.covariance = kept.front().covariance;
}

/// The exact places tying an exact @p candidate (twinsFrom()), polished from a lattice kTwinSteps
/// steps (@p step_xy [m], @p step_theta [rad]) around it when it is near an edge of the cost
/// (nearAnEdge()), and from lattices at half and all of the uniqueness margins. Rays with 6
/// readings, mostly no-returns: an exact place 4.8 cm and 2.5 deg from the exact truth, found by
/// both engines while the truth was not (verification seed 815); a cone's edge sweeping a wall
/// steeply: two exact headings 3.1 deg apart at the truth's position (seed 812); 3 finite readings
/// and 2 no-returns in a furnished room: 3.9 cm and 4.6 deg apart, 10 fine steps (seed 883).
void absorbExactTwins(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                      const RefinementSettings& settings, double step_xy, double step_theta, Candidate& candidate,
                      std::vector<Candidate>& elsewhere)
{
  if (candidate.rms_residual >= kExactRms)
  {
    return;
  }
  std::vector<Pose2> starts;
  if (nearAnEdge(map, readings, candidate, step_xy, step_theta))
  {
    starts = latticeAround(candidate.pose, kTwinSteps * step_xy, kTwinSteps * step_theta);
  }
  for (const double part : { 0.5, 1.0 })
  {
    const std::vector<Pose2> wide =
        latticeAround(candidate.pose, part * options.uniqueness_distance, part * options.uniqueness_angle);
    starts.insert(starts.end(), wide.begin(), wide.end());
  }
  twinsFrom(map, readings, options, settings, starts, kExactRms, candidate, elsewhere);
}

/// Rays meeting their walls within this angle [rad] of one another meet them alike (mirroredTurns()).
constexpr double kAlikeIncidence = 0.05;

/// The angle [rad] in (-pi/2, pi/2] from the normal of the wall @p reading's ray hits at @p pose to
/// the ray; NaN when the ray hits nothing within its range and @p reach (or the sensor is in a wall).
double incidence(const MapRayCaster& map, const Pose2& pose, const Reading& reading, double reach)
{
  const Pose2 sensor = compose(pose, reading.offset);
  if (!map.isFree(sensor.position()))
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const RayHit hit = map.grid().cast(sensor.position(), sensor.heading(), reading.range + reach);
  if (!hit.hit())
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  const Segment& wall = map.grid().segments()[static_cast<std::size_t>(hit.segment)];
  const Vec2 normal(wall.a.y() - wall.b.y(), wall.b.x() - wall.a.x());
  const Vec2 u = sensor.heading();
  const double a = std::atan2(normal.x() * u.y() - normal.y() * u.x(), normal.dot(u));
  return a > kPi / 2.0 ? a - kPi : a <= -kPi / 2.0 ? a + kPi : a;
}

/// The turns [rad] of @p candidate's heading that mirror its rays about their walls' normals: where
/// most of its finite inlier rays (half or more, two or more) meet their walls at about one angle
/// alpha to the normal, turning by -2 alpha has each of them meet its wall at -alpha, at the same
/// range (four sensors square to a rectilinear building). A twin there explains the readings as
/// well, and its basin can be narrower than any lattice's step (verification seed 881, a warehouse
/// scaled by 1.5: the truth turned -1.85 deg and its twin +1.85 deg; the truth's 38 m ray hits a
/// shelf 0.008 rad further round, the polishes from a cell's step away (0.098 rad) never reached
/// it, and the voxel engine found only the twin).
std::vector<double> mirroredTurns(const MapRayCaster& map, const std::vector<Reading>& readings,
                                  const Candidate& candidate, double reach)
{
  std::vector<double> angles;
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const bool ray = std::isfinite(readings[i].range) && !(readings[i].half_angle > 0.0);
    const double a = ray && candidate.inlier_mask[i] ? incidence(map, candidate.pose, readings[i], reach) :
                                                       std::numeric_limits<double>::quiet_NaN();
    if (std::isfinite(a))
    {
      angles.push_back(a);
    }
  }
  std::sort(angles.begin(), angles.end());
  std::vector<double> turns;
  for (std::size_t first = 0, last = 0; first < angles.size(); first = last)
  {
    double sum = 0.0;
    for (last = first; last < angles.size() && angles[last] - angles[first] <= kAlikeIncidence; ++last)
    {
      sum += angles[last];
    }
    const std::size_t alike = last - first;
    const double turn = -2.0 * sum / static_cast<double>(alike);
    if (alike >= 2 && 2 * alike >= angles.size() && std::abs(turn) > 1e-6)
    {
      turns.push_back(turn);
    }
  }
  return turns;
}

/// The twins of @p candidate at its mirrored headings (mirroredTurns()) that tie it, an RMS within
/// the noise of its own (twinsFrom()).
void mirroredTwins(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                   const RefinementSettings& settings, Candidate& candidate, std::vector<Candidate>& elsewhere)
{
  std::vector<Pose2> starts;
  for (const double turn : mirroredTurns(map, readings, candidate, options.range_tolerance))
  {
    starts.emplace_back(candidate.pose.x, candidate.pose.y, wrapAngle(candidate.pose.theta + turn));
  }
  twinsFrom(map, readings, options, settings, starts, candidate.rms_residual + settings.noise_sigma, candidate,
            elsewhere);
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
  const int threads = threadsFor(options.threads);
  std::vector<std::vector<Candidate>> elsewhere(static_cast<std::size_t>(tied));
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads) if (tied >= 2)
  for (long j = 0; j < tied; ++j)
  {
    escapeInPairs(map, readings, options, settings, candidates[static_cast<std::size_t>(j)],
                  elsewhere[static_cast<std::size_t>(j)]);
    settleInNearBasin(map, readings, settings, step_xy, step_theta, candidates[static_cast<std::size_t>(j)]);
    absorbExactTwins(map, readings, options, settings, step_xy, step_theta, candidates[static_cast<std::size_t>(j)],
                     elsewhere[static_cast<std::size_t>(j)]);
    mirroredTwins(map, readings, options, settings, candidates[static_cast<std::size_t>(j)],
                  elsewhere[static_cast<std::size_t>(j)]);
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
