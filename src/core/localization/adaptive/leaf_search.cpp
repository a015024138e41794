// The search of one leaf for a place reaching a consensus (leaf_search.h).
#include "fdml_localization/core/localization/adaptive/leaf_search.h"

#include "fdml_localization/core/localization/ranking.h"

#include <algorithm>
#include <cmath>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Halvings of every axis of the leaf ...
constexpr int kFillDepth = 4;
/// ... or up to this many while the best centre is promising (kPromisingSlack) ...
constexpr int kFillMaxDepth = 6;
/// ... keeping at most this many sub-boxes per level (the best centres), or this many beyond
/// kFillDepth.
constexpr std::size_t kFillBeam = 16;
constexpr std::size_t kFillDeepBeam = 4;

/// A place reaching the target with an RMS under this fraction of noise_sigma, yet not exact, does not end the search:
/// such readings are near noise-free, and an exact place can lie in the same leaf a few millimetres wide where a cone's
/// edge sweeps a corner (verification seed 812: 4 cones, a place of 0.3 mm 9.4 cm and 1.4 deg from the exact truth).
/// Noisy readings leave every place above it: the search then stops as before.
constexpr double kNoiseFreeFraction = 0.1;

/// A place ends a leaf's search only within this fraction of the leaf's size (in x, y and heading) of the leaf: a
/// refinement that goes further found another leaf's place, not this one's (verification seed 826, 5 rays driving:
/// the first sub-box of a 9 cm leaf refined to a place of 6.8 mm 10 cm beyond the leaf's edge, ending its search,
/// while the exact truth lay in the leaf, two halvings deeper). Half a leaf, not none: noisy readings' refinements
/// often stop just past the edge, and searching on after them cost a quarter more time for nothing (`--seed 17`).
constexpr double kOwnPlaceMargin = 0.5;

/// Where a search ends at a place short of exact, the next best sub-boxes of its level refined too (verification seed
/// 838, 5 rays driving: the leaf's best sub-box refined to a local optimum of 7.3 mm 1.8 cm from the exact truth in
/// the same leaf, which ended its search; the next sub-box refines to the truth).
constexpr int kEndStarts = 3;

/// True when @p place lies in @p leaf grown by kOwnPlaceMargin.
bool nearLeaf(const Candidate& place, const PoseBox& leaf)
{
  return leaf.contains(place.pose, kOwnPlaceMargin * (leaf.x1 - leaf.x0), kOwnPlaceMargin * (leaf.t1 - leaf.t0));
}

/// True when @p place ends the search of @p leaf for @p target readings: it reaches the target, exact or not nearly so
/// (kNoiseFreeFraction of @p settings' noise_sigma), and lies nearLeaf().
bool endsLeafSearch(const Candidate& place, const PoseBox& leaf, int target, const RefinementSettings& settings)
{
  const bool nearly_exact =
      place.rms_residual >= kExactRms && place.rms_residual < kNoiseFreeFraction * settings.noise_sigma;
  return netConsensus(place) >= target && !nearly_exact && nearLeaf(place, leaf);
}

/// Deepest sub-boxes a screen verifies (screenLeaf()).
constexpr std::size_t kScreenVerified = 8;

/// The band [m] within which the centre of @p box may miss @p reading while a pose of the box
/// explains it within @p eps: eps, half the box's diagonal in x, y, and half its heading span
/// times the sensor's reach (mounting offset plus range).
double boxBand(const PoseBox& box, const Reading& reading, double eps)
{
  const double reach = reading.offset.position().norm() + (std::isfinite(reading.range) ? reading.range : 0.0);
  return eps + 0.5 * std::hypot(box.x1 - box.x0, box.y1 - box.y0) + 0.5 * (box.t1 - box.t0) * reach;
}

/// A sub-box of a leaf that may still explain the target, with its centre pose verified.
struct SubBox
{
  PoseBox box;
  Candidate centre;
  BoxAgreement agreement;  ///< the centre's at the box's scale
};

/// @p box with its centre verified (eps) and its agreement at the box's own scale: where ranges are
/// long, a 4.7 cm, 0.35 deg box's centre explains 2 of 5 readings within eps while every reading
/// lies within its band, and ranked by the centre's consensus the box holding the truth left the
/// beam (verification seed 103, voxel engine).
SubBox verifiedSubBox(const MapRayCaster& map, const std::vector<Reading>& readings, double eps, const PoseBox& box)
{
  SubBox sub;
  sub.box = box;
  sub.centre = verifiedBox(map, box, readings, eps, sub.agreement);
  return sub;
}

/// The beam's order (closerAgreement()).
bool closerSubBox(const SubBox& a, const SubBox& b)
{
  return closerAgreement(a.agreement, b.agreement);
}

/// Appends to @p kept the halves of @p box (every axis halved, 8) that may still explain
/// @p needed readings (@p test); @p budget counts the box tests down.
void halvesReaching(BoxConsensusTest& test, const PoseBox& box, int needed, long& budget, std::vector<PoseBox>& kept)
{
  for (int c = 0; c < 8; ++c)
  {
    const PoseBox half = box.half(c);
    --budget;
    if (test.reaches(half, needed))
    {
      kept.push_back(half);
    }
  }
}

/// halvesReaching() @p target, each half with its centre verified.
void keptHalves(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                BoxConsensusTest& test, const PoseBox& box, int target, long& budget, std::vector<SubBox>& kept)
{
  std::vector<PoseBox> halves;
  halvesReaching(test, box, target, budget, halves);
  for (const PoseBox& half : halves)
  {
    kept.push_back(verifiedSubBox(map, readings, options.agreement_tolerance, half));
  }
}

/// @p best (the centre of @p best_box) refined, when the refinement stays within two leaves of
/// it (the polish may slide along a continuum) and is better; else @p best.
Candidate refinedNear(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                      RefinementSettings settings, const PoseBox& leaf, const PoseBox& best_box, const Candidate& best)
{
  settings.robust_scale = std::max(options.agreement_tolerance, best_box.x1 - best_box.x0);
  settings.seed_position_error = best_box.x1 - best_box.x0;
  settings.seed_angle_error = best_box.t1 - best_box.t0;
  // The hypothesis: every reading some pose of the sub-box may explain, not only the centre's
  // inliers (a 4.7 cm, 0.35 deg box's centre misses readings of 11 m that its place explains).
  std::vector<bool> hypothesis = best.inlier_mask;
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    hypothesis[i] = hypothesis[i] || readingMayExplain(map, readings[i], best_box, options.range_tolerance);
  }
  Candidate c = refineSeed(map, best.pose, readings, hypothesis, settings);
  const Eigen::Vector3d moved = poseDifference(c.pose, best.pose);
  const bool near =
      moved.head<2>().norm() <= 2.0 * (leaf.x1 - leaf.x0) && std::abs(moved.z()) <= 2.0 * (leaf.t1 - leaf.t0);
  return near && betterCandidate(c, best) ? c : best;
}

/// The halves of @p level's boxes reaching @p target (keptHalves()), the beam at @p depth of them, closest first.
std::vector<SubBox> nextLevel(const MapRayCaster& map, const std::vector<Reading>& readings,
                              const LocalizerOptions& options, BoxConsensusTest& test, const std::vector<SubBox>& level,
                              int target, int depth, long& box_tests)
{
  std::vector<SubBox> next;
  for (const SubBox& b : level)
  {
    keptHalves(map, readings, options, test, b.box, target, box_tests, next);
  }
  const std::size_t beam = std::min(next.size(), depth > kFillDepth ? kFillDeepBeam : kFillBeam);
  std::partial_sort(next.begin(), next.begin() + static_cast<std::ptrdiff_t>(beam), next.end(), closerSubBox);
  next.resize(beam);
  return next;
}

/// Where the search of @p leaf ends at @p refined short of exact, the first kEndStarts of @p boxes (its level's, best
/// first) other than @p done refined too: @p refined becomes the best place found near the leaf (nearLeaf()).
void refineNextBest(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                    const RefinementSettings& settings, const PoseBox& leaf, const std::vector<SubBox>& boxes,
                    const PoseBox& done, Candidate& refined)
{
  int n = 0;
  for (auto b = boxes.begin(); b != boxes.end() && n < kEndStarts && refined.rms_residual >= kExactRms; ++b)
  {
    if (b->box.x0 != done.x0 || b->box.y0 != done.y0 || b->box.t0 != done.t0)
    {
      ++n;
      const Candidate found = refinedNear(map, readings, options, settings, leaf, b->box, b->centre);
      refined = betterCandidate(found, refined) && nearLeaf(found, leaf) ? found : refined;
    }
  }
}

/// firstSubBoxReaching() with @p test's order of readings carried from box to box.
bool firstSubBoxReaching(BoxConsensusTest& test, const PoseBox& box, int needed, int depth, long& budget,
                         PoseBox& found)
{
  if (budget-- <= 0)
  {
    found = box;
    return true;
  }
  if (!test.reaches(box, needed))
  {
    return false;
  }
  if (depth == 0)
  {
    found = box;
    return true;
  }
  for (int c = 0; c < 8; ++c)
  {
    if (firstSubBoxReaching(test, box.half(c), needed, depth - 1, budget, found))
    {
      return true;
    }
  }
  return false;
}

}  // namespace

bool closerAgreement(const BoxAgreement& a, const BoxAgreement& b)
{
  return a.within != b.within ? a.within > b.within : a.cost < b.cost;
}

Candidate verifiedBox(const MapRayCaster& map, const PoseBox& box, const std::vector<Reading>& readings, double eps,
                      BoxAgreement& agreement)
{
  const Pose2 centre = box.centre();
  const PoseEvaluation eval = evaluatePose(map, centre, readings, eps);
  agreement = BoxAgreement{ 0, 0.0 };
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    const double band = boxBand(box, readings[i], eps);
    const double r = eval.residuals[i];
    if (std::isfinite(r) ? std::abs(r) < band : eval.inlier_mask[i])
    {
      ++agreement.within;
      agreement.cost += std::isfinite(r) ? (r / band) * (r / band) : 0.0;
    }
  }
  return candidateFrom(centre, eval);
}

Candidate searchLeafForPlace(const MapRayCaster& map, const LeafBox& leaf, const Candidate& centre,
                             const std::vector<Reading>& readings, const LocalizerOptions& options,
                             const RefinementSettings& settings, int target, long& box_tests)
{
  Candidate best = centre, refined = centre;
  PoseBox best_box = leaf.box;
  bool pending = false;  // best is not refined yet
  std::vector<SubBox> level{ SubBox{ leaf.box, centre, BoxAgreement() } };
  BoxConsensusTest test(map, readings, options.range_tolerance);
  // A place ending the search short of exact: the level's next best sub-boxes are refined too.
  const auto refine = [&](const PoseBox& box, const Candidate& from, const std::vector<SubBox>& boxes) {
    const Candidate found = refinedNear(map, readings, options, settings, leaf.box, box, from);
    refined = betterCandidate(found, refined) ? found : refined;
    if (!endsLeafSearch(refined, leaf.box, target, settings))
    {
      return false;
    }
    refineNextBest(map, readings, options, settings, leaf.box, boxes, box, refined);
    return true;
  };
  for (int depth = 1; !level.empty(); ++depth)
  {
    std::vector<SubBox> next = nextLevel(map, readings, options, test, level, target, depth, box_tests);
    const auto top = std::min_element(
        next.begin(), next.end(), [](const SubBox& a, const SubBox& b) { return betterCandidate(a.centre, b.centre); });
    if (top != next.end() && (depth == 1 || betterCandidate(top->centre, best)))
    {
      best = top->centre;
      best_box = top->box;
      pending = true;
    }
    const bool promising = netConsensus(best) >= target - kPromisingSlack;
    // Refined when promising, or from the last regular level on: most leaves hold no place.
    if (pending && !next.empty() && (promising || depth >= kFillDepth))
    {
      pending = false;
      if (refine(best_box, best, next))
      {
        break;
      }
    }
    // Where no centre is promising, the box closest at its own scale too (long ranges), when
    // promising at that scale.
    const bool close = !next.empty() && next.front().agreement.within >= target - kPromisingSlack;
    if (!promising && close && depth == kFillDepth && top != next.begin() &&
        refine(next.front().box, next.front().centre, next))
    {
      break;
    }
    if (depth >= (promising ? kFillMaxDepth : kFillDepth))
    {
      break;
    }
    level = std::move(next);
  }
  ensureCovariance(map, readings, settings.noise_sigma, refined);
  return refined;
}

bool firstSubBoxReaching(const MapRayCaster& map, const std::vector<Reading>& readings, double tolerance,
                         const PoseBox& box, int needed, int depth, long& budget, PoseBox& found)
{
  BoxConsensusTest test(map, readings, tolerance);
  return firstSubBoxReaching(test, box, needed, depth, budget, found);
}

bool probeLeaf(const MapRayCaster& map, const PoseBox& leaf, const std::vector<Reading>& readings,
               const LocalizerOptions& options, int needed, int depth, Candidate& centre, long& box_tests)
{
  PoseBox found;
  if (!firstSubBoxReaching(map, readings, options.range_tolerance, leaf, needed, depth, box_tests, found))
  {
    return false;
  }
  if (centre.inliers >= 0)
  {
    Candidate c = verifiedCandidate(map, found.centre(), readings, options.agreement_tolerance);
    if (betterCandidate(c, centre))
    {
      centre = std::move(c);
    }
  }
  return true;
}

bool screenLeaf(const MapRayCaster& map, const PoseBox& leaf, const std::vector<Reading>& readings,
                const LocalizerOptions& options, int needed, int depth, Candidate& centre, long& box_tests)
{
  std::vector<PoseBox> level{ leaf };
  BoxConsensusTest test(map, readings, options.range_tolerance);
  for (int d = 0; d < depth && !level.empty(); ++d)
  {
    std::vector<PoseBox> next;
    for (const PoseBox& box : level)
    {
      halvesReaching(test, box, needed, box_tests, next);
    }
    level = std::move(next);
  }
  const std::size_t step = std::max<std::size_t>(1, level.size() / kScreenVerified);
  for (std::size_t j = 0; j < level.size(); j += step)
  {
    Candidate c = verifiedCandidate(map, level[j].centre(), readings, options.agreement_tolerance);
    if (centre.inliers < 0 || betterCandidate(c, centre))
    {
      centre = std::move(c);
    }
  }
  return !level.empty();
}

std::vector<Candidate> leafLatticeBests(const MapRayCaster& map, const std::vector<const LeafBox*>& leaves,
                                        std::size_t max_leaves, const std::vector<Reading>& readings, double eps)
{
  const std::size_t step = std::max<std::size_t>(1, leaves.size() / std::max<std::size_t>(1, max_leaves));
  const auto at = [](double lo, double hi, int j) { return lo + (hi - lo) * (j + 0.5) / kLeafLattice; };
  std::vector<Candidate> lattice_best;
  for (std::size_t l = 0; l < leaves.size(); l += step)
  {
    const PoseBox& b = leaves[l]->box;
    Candidate leaf_best;
    leaf_best.inliers = -1;
    for (int i = 0; i < kLeafLattice * kLeafLattice * kLeafLattice; ++i)
    {
      const Pose2 pose(at(b.x0, b.x1, i % kLeafLattice), at(b.y0, b.y1, (i / kLeafLattice) % kLeafLattice),
                       at(b.t0, b.t1, i / (kLeafLattice * kLeafLattice)));
      Candidate c = verifiedCandidate(map, pose, readings, eps);
      if (leaf_best.inliers < 0 || betterCandidate(c, leaf_best))
      {
        leaf_best = std::move(c);
      }
    }
    lattice_best.push_back(std::move(leaf_best));
  }
  return lattice_best;
}

RefinementSettings latticeRefinement(const LocalizerOptions& options, double cell_xy, double cell_theta)
{
  RefinementSettings settings;
  settings.agreement_tolerance = options.agreement_tolerance;
  settings.robust_scale = std::max(options.agreement_tolerance, cell_xy);
  settings.seed_position_error = cell_xy;
  settings.seed_angle_error = cell_theta;
  return settings;
}

}  // namespace core
}  // namespace fdml_localization
