/**
 * @file ranking.h
 * @brief The one ranking of candidate poses and the one ambiguity rule, used by both engines,
 *        the node, fdml_localize, fdml_bench and the demo.
 *
 * Unknown obstacles only shorten readings, so a reading the map contradicts at a pose (measured
 * longer than the map allows, or no return where the map has a wall in range) counts against
 * that pose: candidates rank by net consensus (inliers - contradicted), then fewer contradicted
 * readings, then lower RMS residual. Without contradicted readings this is "most inliers, then
 * lowest RMS" (the paper's order).
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"

#include <vector>

namespace fdml_localization
{
namespace core
{
/// An RMS below this is exact: the rounding of a polish [m].
constexpr double kExactRms = 1e-6;

/// Net consensus of a candidate: inliers minus the readings the map contradicts at its pose.
inline int netConsensus(const Candidate& c)
{
  return c.inliers - c.contradicted;
}

/**
 * @brief The ranking order on raw figures (so that evaluations and candidates share it): the
 *        larger net consensus first, then fewer contradicted readings, then lower RMS [m].
 */
bool rankedBefore(int inliers_a, int contradicted_a, double rms_a, int inliers_b, int contradicted_b, double rms_b);

/// The ranking order on candidates (see rankedBefore()).
bool betterCandidate(const Candidate& a, const Candidate& b);

/// True when @p a and @p b tie exactly: the same net consensus and contradicted readings, both RMS
/// below kExactRms (what orders them then is the rounding of their polish).
bool exactTie(const Candidate& a, const Candidate& b);

/// True when @p a and @p b are one place: closer than @p distance [m] in position and than
/// @p angle [rad] in heading (the uniqueness margins; rankAndDeduplicate() keeps one of them).
bool withinMargins(const Pose2& a, const Pose2& b, double distance, double angle);

/**
 * @brief Sorts best first and drops every candidate closer than (@p distance [m], @p angle
 *        [rad]) to a better one kept before it; keeps at most @p max_candidates.
 */
std::vector<Candidate> rankAndDeduplicate(std::vector<Candidate> candidates, double distance, double angle,
                                          int max_candidates);

/**
 * @brief Two optima closer than (@p distance, @p angle) are one candidate, but when they tie
 *        (same net consensus, RMS within @p noise [m]) the answer may be either: each candidate of
 *        @p kept (the deduplicated list) widens its covariance until it covers, within 3
 *        standard deviations, every candidate of @p all (the list before deduplication) that
 *        ties it and was dropped as its duplicate.
 */
void absorbTiedDuplicates(const std::vector<Candidate>& all, double distance, double angle, double noise,
                          std::vector<Candidate>& kept);

/**
 * @brief rankAndDeduplicate(), then absorbTiedDuplicates() of every candidate dropped into the
 *        one kept near it: the merge of polished candidates. Dropped silently, a tie can be the
 *        truth: with 4 readings, an exact place 8.3 cm and 3.7 deg from the truth's, its RMS
 *        smaller by rounding, was kept with a covariance of 7 mm and 0.3 deg.
 * @param noise [m] the RMS within which two candidates of the same net consensus tie
 */
std::vector<Candidate> rankAndAbsorbDuplicates(const std::vector<Candidate>& candidates, double distance, double angle,
                                               double noise, int max_candidates);

/**
 * @brief The one ambiguity rule: a result's best candidate is unambiguous when it is the only
 *        candidate, or when its net consensus is strictly larger than the second's. Candidates
 *        tied on net consensus are different places that explain the readings equally well
 *        (a symmetric room): no single pose is claimed.
 */
bool isUnambiguous(const Result& result);

}  // namespace core
}  // namespace fdml_localization
