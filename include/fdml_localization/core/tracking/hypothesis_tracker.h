/**
 * @file hypothesis_tracker.h
 * @brief Pose hypotheses across time (ROS-free): each hypothesis is a map -> odom transform, so
 *        odometry carries it between readings; its uncertainty box grows with the distance and
 *        the rotation travelled since its last fix (AMCL-like odom_alpha1..4). Every update
 *        re-solves each hypothesis locally over the last k readings (local_solve.h: a
 *        conservative box search around its prediction, then the shared refinement); support is
 *        a decayed sum of net consensus, so places that explain one batch equally are told apart
 *        as the robot moves, and one spoiled batch neither moves nor drops a well-supported
 *        hypothesis.
 *
 * Poses: the readings of an update are relative to the base at the odometry pose `reference`
 * (the node's batches: the base at the first reading); a hypothesis's pose of the base at any
 * odometry pose o is map_to_odom (+) o. Each hypothesis also carries the covariance of that pose
 * (pose_filter.h: odometry steps spread it, fixes shrink it), counting of each fix only what no
 * one direction's readings fix alone, except where a prediction already within the publishing
 * margins agrees with the fix (TrackerOptions::fix_gate); it is published only while within
 * those margins (publish_max_xy, publish_max_theta). A fix narrows a hypothesis whose 3 sigma
 * reaches beyond its (capped) box only when no other place of that 3-sigma region may explain
 * as many readings (onlyPlace()). A global search's candidates may join late, and places it
 * missed may come with a later one: seed() carries new places through the remembered batches
 * first, and a hypothesis a search brought is published only after confirm_searches more.
 */
#pragma once

#include "fdml_localization/core/localization/adaptive/adaptive_search.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/voxel/box_occupancy.h"
#include "fdml_localization/core/tracking/local_solve.h"
#include "fdml_localization/core/tracking/pose_filter.h"

#include <Eigen/Core>

#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace fdml_localization
{
namespace core
{
/// Options of the tracker. validate() lists every out-of-range value.
struct TrackerOptions
{
  /// Net consensus a pose needs to count as a fix, as a fraction of k (k' = ceil(fraction k),
  /// at least 3), in (0, 1].
  double min_consensus_fraction = 0.6;
  // Odometry noise, as AMCL's odom_alpha1..4 (>= 0): sigma_theta = alpha1 |rot| + alpha2 |trans|,
  // sigma_xy = alpha3 |trans| + alpha4 |rot|. Each odometry step adds these to the hypothesis's
  // covariance (pose_filter.h); the search box's half-widths are the larger of 3 standard
  // deviations of that covariance and box_min + 3 sigma summed over the motion since the last fix.
  double odom_alpha1 = 0.2;     ///< rotation noise from rotation [rad/rad]
  double odom_alpha2 = 0.2;     ///< rotation noise from translation [rad/m]
  double odom_alpha3 = 0.2;     ///< translation noise from translation [m/m]
  double odom_alpha4 = 0.2;     ///< translation noise from rotation [m/rad]
  double box_min_xy = 0.1;      ///< half-width of the box right after a fix [m], (0, box_max_xy]
  double box_min_theta = 0.05;  ///< ... in theta [rad], (0, box_max_theta]
  double box_max_xy = 1.0;      ///< the box stops growing here [m]
  double box_max_theta = 0.6;   ///< ... in theta [rad], <= pi
  double cell_xy = 0.05;        ///< leaf size of the local box search [m], (0, box_min_xy]
  double cell_theta = 0.025;    ///< ... in theta [rad], (0, box_min_theta]
  /// support <- decay support + net consensus / k per update; a miss adds the best consensus
  /// (below k') refined in its box, 0 for an empty box. In (0, 1).
  double support_decay = 0.95;
  double min_support = 3.0;     ///< a clearly supported hypothesis has at least this support, > 0
  double support_margin = 1.5;  ///< ... and this much more than any other, >= 0
  /// ... and missed at most this many updates in a row (it coasts on odometry meanwhile, its
  /// covariance growing), none of them a conflict, >= 0
  int tolerated_misses = 20;
  /// A miss in which at least this many readings contradict every refined pose of the box
  /// (longer than the map allows: no unknown obstacle explains them), a fix contradicting this
  /// many, or a fix whose fused pose contradicts this many more than the fix, is a conflict: the
  /// hypothesis is not published until a fix without one. >= 1
  int conflict_readings = 2;
  double publish_max_xy = 0.1;       ///< ... and 3 sigma of its position is at most this [m], > 0
  double publish_max_theta = 0.087;  ///< ... and 3 sigma of its heading at most this [rad], > 0
  int max_misses = 30;               ///< a hypothesis missing this many updates in a row is dropped, > tolerated_misses
  /// Every hypothesis missed this many updates in a row, none is clearly supported and none with
  /// a fix coasts (a conflict, or more than tolerated_misses misses): lost, >= 1
  int lost_updates = 6;
  int max_hypotheses = 10;            ///< the least supported beyond this are dropped, >= 1
  double merge_distance = 0.1;        ///< hypotheses closer than this [m] ...
  double merge_angle = 0.1;           ///< ... and this [rad] are merged (the better kept)
  double agreement_tolerance = 0.05;  ///< eps [m] (the node takes the localizer's)
  double range_tolerance = 0.02;      ///< tau [m] (the node takes the localizer's)
  int max_seeds = 3;                  ///< leaves refined per local solve
  /// A fix counts only the precision it keeps when the readings of any one direction (mounting
  /// headings within this [rad] of each other: one sensor, a sector of a scanner) are wrong, as
  /// when a person walks in front of that sensor; [0, pi], < 0 = off (LocalSolveSettings).
  double direction_group = 0.25;
  /// ... except where the hypothesis already holds that precision: while its covariance is
  /// within the publishing margins (publish_max_xy, publish_max_theta), a fix whose squared
  /// Mahalanobis distance from the prediction (under the prediction's covariance plus the fix's
  /// own) is at most this, and at most the quantile of the same probability over the r
  /// directions the loss alone fixes (chi-square, r degrees of freedom), counts that loss only
  /// up to the prediction's covariance. The prediction, fixed by earlier updates under this rule
  /// and carried by odometry, is then a second witness (to its own precision, no further): one
  /// sensor agreeing with it keeps a direction fixed (a corridor's end wall, one side while a
  /// person walks along the other). A fix beyond the gate, or beyond that quantile while within
  /// the margins, disagrees: the fix or the prediction is wrong (a person read as a wall at a
  /// slant), and the fix counts only up to its disagreement (its covariance gains d d^T, d its
  /// difference from the prediction [m, m, rad]). 11.34: 99 % of a true fix (3 degrees of
  /// freedom). [0, 1e6], 0 = never (every fix counts its loss).
  double fix_gate = 11.34;
  /// Each fix's covariance is multiplied by this before it is fused, in [1, 1000]. Batches that
  /// slide by s of their k readings share k - s readings with the previous one, so their fixes
  /// are not independent: a filter taking each as new evidence would count every reading k / s
  /// times and grow overconfident (the node sets k / ~batch_stride).
  double fix_covariance_scale = 1.0;
  /// A hypothesis a global search brought is published only after this many later global
  /// searches were merged (seed()) while it stood: one search can miss places alike to it (a
  /// continuum of poses holding several, a full candidate list), a later one may bring them.
  /// The caller starts those searches while awaitingConfirmation(). A hint's hypotheses need
  /// none. [0, 100]; 0 = publish without. Default 1: a search returns only the places of the
  /// largest consensus, so where unknown obstacles hide readings of the true place (people and
  /// chairs next to the robot), a place alike explaining one reading more is its only
  /// candidate and a search alone would publish it; the later search, on readings the
  /// obstacles spoil differently, brings the true place to compete (in the demo's kidnaps 6 of
  /// 8,000 were published wrong with 0, none with 1, for 0.2 s more to the first fix). Each
  /// costs a global search before a first fix, and where look-alikes tie on the remembered
  /// readings (long corridors) it holds the fix until the drive tells them apart; 2 on maps
  /// with identical rooms.
  int confirm_searches = 1;
  /// Batches remembered before a global search's batch (update() remembers every batch): a new
  /// place it brings is carried through them and those after it before it joins, starting from
  /// the best hypothesis's support (what the best earned before them counts for both; what they
  /// hold must tell the places apart). [0, 1000]; 0 = none (only the batches
  /// since the search's). With confirm_searches: 16 in twin rooms; in the office drive 16 moved
  /// the first fix from 23 to 31 s, so not the default.
  int history_batches = 0;
};

/// Batches the tracker remembers after a global search's batch (seed()'s @p since): a search
/// running that long loses the older ones' evidence.
constexpr int kMaxCatchUp = 100;

/// Every problem of @p options, as "NAME = VALUE is out of range; allowed: RANGE" (@p name maps
/// an option's name to the caller's; empty = the option's own name).
std::vector<std::string> validate(const TrackerOptions& options,
                                  const std::function<std::string(const std::string&)>& name = {});

/// One pose hypothesis.
struct Hypothesis
{
  std::uint64_t id = 0;     ///< unique in the tracker's life
  Pose2 map_to_odom;        ///< the hypothesis [m, rad]
  double travelled = 0.0;   ///< odometry distance since the last fix [m]
  double turned = 0.0;      ///< odometry rotation since the last fix [rad]
  double support = 0.0;     ///< decayed sum of net consensus / k
  int misses = 0;           ///< updates in a row without a fix
  bool conflicted = false;  ///< the last update was in conflict (TrackerOptions::conflict_readings)
  /// Of the base's pose map_to_odom (+) the tracker's last reference (x, y, theta) [m^2, rad^2],
  /// counting of each fix only what no one direction's readings fix alone
  /// (LocalSolveOutcome::direction_loss): a person in front of the one sensor that fixes a
  /// direction moves neither the pose nor its claimed precision. The pose, its search box, the
  /// publishing rule and the published covariance follow it.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  int fixes = 0;          ///< updates with a fix
  Candidate last_fix;     ///< the last fix (pose of the base at its update's reference)
  int confirmations = 0;  ///< global searches merged while it stood (TrackerOptions::confirm_searches)
};

/// The tracker's state.
enum class TrackState
{
  Empty,      ///< no hypothesis
  Tracking,   ///< exactly one hypothesis is clearly supported
  Ambiguous,  ///< hypotheses, none clearly supported
  Lost        ///< every hypothesis missed lost_updates updates in a row, none clearly supported or coasting
};
const char* toString(TrackState state);

/// What one update did.
struct UpdateReport
{
  int fixed = 0;           ///< hypotheses with a fix
  int missed = 0;          ///< hypotheses without one
  int dropped = 0;         ///< hypotheses dropped (missed max_misses times, merged, beyond the bound)
  int min_consensus = 0;   ///< the k' used
  int best_possible = 0;   ///< the largest consensus any box may hold (over every hypothesis)
  bool truncated = false;  ///< a box search hit its budget
};

/// What a hint (initialpose) gave.
struct HintOutcome
{
  bool accepted = false;  ///< at least one pose in the hint's box explains k' readings
  /// The best net consensus found in the box (at its centre when no pose of it may reach k')
  int best_consensus = 0;
  int min_consensus = 0;  ///< the k' required
  int hypotheses = 0;     ///< hypotheses seeded
};

/// A batch of readings relative to the base at the odometry pose @p reference (the node's batch).
struct TrackerBatch
{
  std::vector<Reading> readings;
  Pose2 reference;
};

/// See the file comment. Not thread-safe.
class HypothesisTracker
{
public:
  /// @throws std::invalid_argument listing every problem of @p options, or for a null map
  HypothesisTracker(std::shared_ptr<const MapRayCaster> map, const TrackerOptions& options);

  /**
   * @brief Merges a global search's candidates: one duplicating a hypothesis raises its support
   *        to @p support at least; every other becomes a new hypothesis with the larger of
   *        @p support and the best hypothesis's support, first carried through the remembered
   *        batches (history_batches before the candidates' batch, that batch, and the @p since
   *        batches remembered after it, oldest first) alone, then joining the others. Every
   *        hypothesis that stood before counts one more confirmation.
   * @param reference the odometry pose of the base the candidates' poses refer to
   * @param since batches update() remembered after the candidates' batch (at most kMaxCatchUp)
   */
  void seed(const std::vector<Candidate>& candidates, const Pose2& reference, double support, std::size_t since = 0);

  /**
   * @brief A user's hint: the poses in @p box (around the base at @p reference) that explain
   *        k' of @p readings replace every hypothesis, each with support min_support; when none
   *        does, the hypotheses are kept and the outcome says the best consensus found.
   */
  HintOutcome seedFromHint(const PoseBox& box, const std::vector<Reading>& readings, const Pose2& reference);

  /// Re-solves every hypothesis over @p readings (relative to the base at odometry pose
  /// @p reference) in its box around its prediction; updates support, merges, bounds. Remembers
  /// the batch (seed()), with or without hypotheses: call it for every batch.
  UpdateReport update(const std::vector<Reading>& readings, const Pose2& reference);

  /// Drops every hypothesis (a relocalization).
  void clear();
  /// Replaces the hypotheses (carried over to a tracker of a new map of the same frame).
  void restore(std::vector<Hypothesis> hypotheses);

  /// The hypotheses, best (most supported) first.
  const std::vector<Hypothesis>& hypotheses() const
  {
    return hypotheses_;
  }
  /// The clearly supported hypothesis (see TrackerOptions: min_support, support_margin,
  /// tolerated_misses, conflict_readings, publish_max_xy, publish_max_theta, confirm_searches),
  /// or null.
  const Hypothesis* clearlySupported() const;
  /// True when the best hypothesis would be clearly supported but for its confirmations: the
  /// caller should run a global search and seed() its candidates.
  bool awaitingConfirmation() const;
  /**
   * @brief Whether the caller should start a global search now (the node's rule): while
   *        @p searching (relocalizing, or always in continuous mode) when the tracker is empty or
   *        lost, or when no hypothesis found a fix for @p interval updates and @p since_search
   *        updates came since the last search (hypotheses that keep finding fixes are only
   *        ambiguous: another search adds aliases, not evidence); in any mode while a place
   *        awaits confirmation.
   */
  bool wantsGlobalSearch(bool searching, int since_search, int interval) const;
  TrackState state() const;
  /// Updates in a row in which no hypothesis had a fix (0 after a fix).
  int failedUpdates() const
  {
    return failed_updates_;
  }
  /// The k' for @p k readings.
  int minConsensus(int k) const;
  /// The uncertainty box of @p hypothesis around its pose of the base at @p reference.
  PoseBox boxOf(const Hypothesis& hypothesis, const Pose2& reference) const;
  const TrackerOptions& options() const
  {
    return options_;
  }

private:
  LocalSolveSettings solveSettings(int k) const;
  /// Adds the odometry motion from the last reference to @p reference to every hypothesis.
  void accumulateMotion(const Pose2& reference);
  /// Re-solves @p h in its box; true on a fix.
  bool updateOne(Hypothesis& h, const std::vector<Reading>& readings, const Pose2& reference,
                 const LocalSolveSettings& settings, UpdateReport& report);
  /// Carries @p h by one of @p found's fixes in @p box (chooseFix(), fused with fixNoise(),
  /// narrowing only by onlyPlace()); the update is a conflict when the fix, or the fused pose
  /// beyond its fix, leaves conflict_readings readings longer than the map allows, and the
  /// fused pose's covariance then also covers the fix.
  void takeFix(Hypothesis& h, const std::vector<Reading>& readings, const Pose2& reference, const PoseBox& box,
               const LocalSolveOutcome& found);
  /// The covariance a new hypothesis at @p candidate starts with.
  Eigen::Matrix3d initialCovariance(const Candidate& candidate) const;
  /// The covariance of the smallest search box (box_min_xy, box_min_theta as 3 sigma).
  Eigen::Matrix3d leastCovariance() const;
  /// The index of the fix (of at least one) that carries a hypothesis predicted at @p predicted.
  std::size_t chooseFix(const std::vector<Candidate>& fixes, const Pose2& predicted) const;
  /// The covariance with which fix @p i of @p found is fused into @p h, predicted at
  /// @p predicted [m^2, rad^2].
  Eigen::Matrix3d fixNoise(const Hypothesis& h, const Pose2& predicted, const LocalSolveOutcome& found,
                           std::size_t i) const;
  /// False when the fix behind @p fused would narrow a hypothesis whose @p predicted covariance
  /// reaches beyond its search @p box to within the box, while another place of its 3-sigma
  /// region may explain as many of @p readings (onlyPlaceInRegion()): the fix is then taken
  /// without its precision.
  bool onlyPlace(const Eigen::Matrix3d& predicted, const PoseBox& box, const FusedPose& fused,
                 const std::vector<Reading>& readings, const Candidate& fix) const;
  /// True when 3 standard deviations of @p covariance are within publish_max_xy and
  /// publish_max_theta.
  bool withinMargins(const Eigen::Matrix3d& covariance) const;
  /// Merges duplicates, drops hypotheses that missed too often, sorts, bounds the count.
  int prune();
  /// True when poses @p a and @p b are within merge_distance and merge_angle.
  bool samePlace(const Pose2& a, const Pose2& b) const;
  /// The hypothesis whose pose of the base at @p reference is samePlace() as @p pose, or null.
  Hypothesis* holding(const Pose2& pose, const Pose2& reference);
  /// The best hypothesis when it meets every publishing condition but confirm_searches, or null.
  const Hypothesis* supportedUnconfirmed() const;
  /// Adds a hypothesis per candidate not duplicating one (whose support rises to @p support),
  /// with @p support, @p confirmations and initialCovariance() plus @p spread.
  void add(const std::vector<Candidate>& candidates, const Pose2& reference, double support, int confirmations,
           const Eigen::Matrix3d& spread);
  /// Carries the hypotheses alone through remembered batches [@p first, end) (nothing remembered).
  void replay(std::size_t first);
  /// The odometry noise (as a covariance [m^2, rad^2]) of the motion over remembered batches
  /// [@p first, @p last).
  Eigen::Matrix3d replaySpread(std::size_t first, std::size_t last) const;

  std::shared_ptr<const MapRayCaster> map_;
  TrackerOptions options_;
  BoxOccupancy occupancy_;
  std::vector<Hypothesis> hypotheses_;
  bool have_reference_ = false;
  Pose2 last_reference_;
  int failed_updates_ = 0;
  std::uint64_t next_id_ = 1;
  std::deque<TrackerBatch> history_;  ///< the last batches updated, oldest first (seed())
  bool replaying_ = false;            ///< update() carries new hypotheses: remember nothing
};

}  // namespace core
}  // namespace fdml_localization
