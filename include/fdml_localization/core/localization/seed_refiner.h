/**
 * @file seed_refiner.h
 * @brief The steps of refineSeed() (robust_search.h): the state of one refinement. Internal to
 *        the robust search; declared here so that its steps can live in two sources
 *        (seed_refinement.cpp: polishes and rounds; seed_refinement_starts.cpp: escapes, the
 *        multi-start and the final polish of the best candidates).
 */
#pragma once

#include "fdml_localization/core/localization/robust_search.h"
#include "fdml_localization/core/localization/seed_search.h"
#include "fdml_localization/core/util/stopwatch.h"

#include <algorithm>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// Readings selected by @p use.
inline int countUsed(const std::vector<bool>& use)
{
  return static_cast<int>(std::count(use.begin(), use.end(), true));
}

/// The state of one refinement (refineSeed()): the best pose so far and the steps that try to
/// improve it. Internal to the robust search; its steps are in seed_refinement.cpp and
/// seed_refinement_starts.cpp.
class Refiner
{
public:
  Refiner(const MapRayCaster& map, const Pose2& seed, const std::vector<Reading>& readings,
          const std::vector<bool>& hypothesis, const RefinementSettings& settings,
          const std::vector<Pose2>& region_starts)
    : map_(map)
    , seed_(seed)
    , readings_(readings)
    , hypothesis_(hypothesis)
    , settings_(settings)
    , region_starts_(region_starts)
    , best_pose_(seed)
    , best_(evaluatePose(map, seed, readings, settings.agreement_tolerance))
    , seed_residuals_(best_.residuals)
  {}

  void firstPolish();
  void dropShortened();
  void localSearch();
  void polishRounds();
  void escapes();
  void multiStart();
  /// Polishes from each of @p poses (at most kRegionPolishes of them, spread over the list)
  /// where every reading agrees within @p gate [m], moved off walls within @p reach [m] first,
  /// collecting what they reach for ties(); none once @p deadline has passed.
  void enumerate(const std::vector<Pose2>& poses, double gate, double reach, const Deadline& deadline);
  Candidate candidate() const;
  std::vector<Candidate> ties() const;  ///< the optima multiStart() reached tying the best

private:
  /// Adopts a polished pose (or a shorter step to it) explaining more readings or a lower RMS.
  bool consider(const PolishOutcome& polished, bool pull_back = true);
  /// The polish does not see no-return readings (nor walls its rays newly hit): a step from the
  /// best pose that contradicts more readings is tried again at fractions of its length.
  bool pullBack(const PolishOutcome& polished);
  PolishOutcome polish(const Pose2& start, const std::vector<bool>& use, double scale) const;
  /// Graduated robustness: the Cauchy scale shrinks from about the seed's error to eps, so
  /// readings cut short by unknown obstacles lose their pull as the pose settles.
  void annealFrom(const Pose2& start, const std::vector<bool>& use);
  /// A reading whose ray grazes a vertex at the optimum jumps there, and its jump holds a
  /// polish away from the optimum (a heading mirrored about a wall's normal explains the other
  /// readings almost as well). Polish at a fine Cauchy scale, which discounts the jump, then
  /// again without the reading left worst; keep whatever improves.
  void fineFrom(const Pose2& start, const std::vector<bool>& use);
  /// The multi-start's readings: the hypothesis's finite readings and the best pose's inliers.
  std::vector<bool> hypothesisAndInliers() const;
  /// The finite-range inliers of the best pose, without reading @p drop (-1: none).
  std::vector<bool> finiteInliers(int drop) const;
  /// finiteInliers() without reading @p drop nor the others pointing its way (parallelRays()).
  std::vector<bool> withoutParallel(int drop) const;
  std::vector<int> escapeTries(bool one_per_direction) const;
  /// Leaves out each pair of escapeTries(true), with their parallel siblings; true at the first
  /// improvement.
  bool escapePairs();

  const MapRayCaster& map_;
  const Pose2 seed_;
  const std::vector<Reading>& readings_;
  const std::vector<bool>& hypothesis_;
  const RefinementSettings settings_;  ///< a copy: a caller may pass a temporary
  const std::vector<Pose2>& region_starts_;
  Pose2 best_pose_;
  PoseEvaluation best_;
  const std::vector<double> seed_residuals_;
  Eigen::Matrix3d best_cov_ = Eigen::Matrix3d::Identity() * 1e6;
  bool collecting_ = false;
  std::vector<Candidate> reached_;  ///< every polish result of multiStart() (collect_ties)
};

/**
 * @brief The final polish of a candidate tied at the best net consensus (robustSearch()):
 *        refineSeed() with settings.collect_ties from @p candidate's pose and its seed's region
 *        starts. When @p enumerate and that multi-start reached another optimum tying it beyond
 *        the uniqueness margins, the region holds several optima (readings that leave the place
 *        ambiguous) and a dozen spread starts can miss some: then every pose of
 *        seed.region_poses where all readings agree within @p gate [m] is polished from too
 *        (Refiner::enumerate(), until @p deadline, LocalizerOptions::deadline from the search's
 *        start). @p candidate is improved in place (its support kept), its covariance widened over
 *        the ties within the margins, both settled along continua.
 * @return the distinct other optima tying it, ranked, at most options.max_candidates
 */
std::vector<Candidate> polishTiedCandidate(const MapRayCaster& map, const std::vector<Reading>& readings,
                                           const SearchSeed& seed, const RefinementSettings& settings,
                                           const LocalizerOptions& options, double gate, bool enumerate,
                                           const Deadline& deadline, Candidate& candidate);

}  // namespace core
}  // namespace fdml_localization
