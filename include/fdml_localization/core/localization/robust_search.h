/**
 * @file robust_search.h
 * @brief The later stages every engine shares: exact-ray-cast verification of a pose
 *        (inlier mask, RMS residual), the continuous polish (Levenberg-Marquardt on
 *        (x, y, theta) with analytic derivatives of the exact ray cast, covariance estimate),
 *        and duplicate removal and ranking of candidates.
 */
#pragma once

#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/Core>

#include <vector>

namespace fdml_localization
{
namespace core
{
/// The agreement of one pose with a batch of readings, by exact ray casts on the polygon.
struct PoseEvaluation
{
  std::vector<bool> inlier_mask;  ///< per reading: agrees within eps
  std::vector<double> residuals;  ///< h(q (+) g_i) - d_i [m]; NaN for no-return readings or a
                                  ///< sensor outside free space
  int inliers = 0;
  /// Readings the map contradicts: measured longer than h + eps, or no return where the map has
  /// a wall within max_range - eps. Unknown obstacles only shorten readings, so none of these
  /// is explained by one.
  int contradicted = 0;
  double rms = 0.0;  ///< RMS of the residuals of the finite-range inliers [m]
};

/**
 * @brief The reading @p reading predicts from sensor pose @p sensor: the exact ray cast for a
 *        ray (half_angle 0), the exact cone cast (cone_cast.h) for a cone; +inf when nothing lies
 *        within @p max_range [m].
 */
double predictedRange(const MapRayCaster& map, const Pose2& sensor, const Reading& reading, double max_range);

/**
 * @brief @p reading's residual at robot pose @p pose [m], the one rule every count of agreeing
 *        readings applies (evaluatePose(), consensusWithin(), agreementScore()): h - d for a
 *        finite range (h: predictedRange(), looking no further than d + @p reach, +inf beyond);
 *        for a no-return reading, min(0, h - max_range) (0: nothing within its range, as
 *        measured). NaN when the sensor lies outside free space. The reading agrees within eps
 *        when |residual| < eps; it is contradicted when residual <= -eps (measured longer than
 *        the map allows, which no unknown obstacle explains).
 */
double readingResidual(const MapRayCaster& map, const Pose2& pose, const Reading& reading, double reach = kInf);

/**
 * @brief Where @p reading's residual (readingResidual()) changes sign between the poses @p a and
 *        @p b along @p direction from @p pose (pose + s direction; s [m] for a unit translation),
 *        its residuals there @p r_a and @p r_b finite and of opposite signs: bisected 24 times (a
 *        4 m stretch down to 0.25 um), the end of the last bracket with the smaller residual. A
 *        residual that is not finite on the way (the sensor outside free space) ends the bisection.
 * @return the offset s of that end
 */
double residualSignChange(const MapRayCaster& map, const Pose2& pose, const Reading& reading,
                          const Eigen::Vector3d& direction, double a, double b, double r_a, double r_b);

/// Every reading's readingResidual() at @p pose [m] (NaN where its sensor lies outside free space).
std::vector<double> poseResiduals(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings);

/// evaluatePose() from the readings' residuals (poseResiduals()) at one pose: one cast per
/// reading serves several tolerances @p eps [m].
PoseEvaluation evaluateResiduals(const std::vector<double>& residuals, const std::vector<Reading>& readings,
                                 double eps);

/**
 * @brief Verifies @p pose: reading i agrees when its sensor position q (+) g_i is in free
 *        space and |h(q (+) g_i) - d_i| < eps (h: predictedRange(), the cone cast for a cone
 *        reading), or, for a no-return reading (d_i = +inf),
 *        when h(q (+) g_i) > max_range_i - eps. A reading the map contradicts (see
 *        PoseEvaluation::contradicted) counts against the pose in the ranking.
 * @param eps agreement tolerance [m]
 */
PoseEvaluation evaluatePose(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                            double eps);

/// Result of polishPose().
struct PolishOutcome
{
  Pose2 pose;
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();  ///< of (x, y, theta)
  int iterations = 0;
};

/**
 * @brief A Gaussian prior on the pose for polishPose(): a tracker's prediction and its
 *        information (the inverse of its covariance) [1/m^2, 1/rad^2]. The polish then
 *        minimises the readings' cost plus noise_sigma^2 (p - mean)^T information (p - mean), the
 *        most probable pose given the readings and the prediction, so that it stays at the
 *        prediction along a direction the readings leave undetermined (a corridor's axis)
 *        instead of sliding along it. A zero information is no prior.
 */
struct PosePrior
{
  Pose2 mean;
  Eigen::Matrix3d information = Eigen::Matrix3d::Zero();
};

/**
 * @brief Nonlinear least squares on the finite-range readings selected by @p use, from
 *        @p start: Levenberg-Marquardt on (x, y, theta) with the analytic derivative of the exact
 *        ray cast (the hit edge's normal), or of the exact cone cast for a cone reading
 *        (coneRangeDerivative()). A ray that leaves free space or misses costs a
 *        constant penalty, so the polish does not walk through walls. A no-return reading
 *        selected (range +inf, a finite max_range) is a one-sided bound: where the map has a wall
 *        within max_range, the range short of it is a residual (same loss); it adds nothing to
 *        the covariance.
 * @param robust_scale Cauchy loss scale [m]; 0 = plain least squares
 * @param noise_sigma lower bound on the residual standard deviation used for the covariance [m]
 * @param prior a prior on the pose (PosePrior); the covariance returned is still the readings'
 *        alone, so that a tracker can fuse it with its prediction
 */
PolishOutcome polishPose(const MapRayCaster& map, const Pose2& start, const std::vector<Reading>& readings,
                         const std::vector<bool>& use, double robust_scale, int max_iterations, double noise_sigma,
                         const PosePrior& prior = PosePrior());

/**
 * @brief Gives @p candidate, when its covariance is zero (a verified pose no polish moved: a
 *        seed's start, a lattice or sub-box centre), the covariance polishPose() would give at
 *        its pose over its inliers (no step taken) [m^2, rad^2]: no candidate leaves with a zero
 *        covariance, a false certainty.
 * @param noise_sigma lower bound on the residual standard deviation [m], as in polishPose()
 */
void ensureCovariance(const MapRayCaster& map, const std::vector<Reading>& readings, double noise_sigma,
                      Candidate& candidate);

/**
 * @brief What the covariance of @p pose (from the finite readings selected by @p use, as
 *        polishPose() computes it) gains when the readings of one direction are all wrong: a
 *        person in front of one sensor, or hiding a sector of a scanner, shifts every reading
 *        the robot takes that way alike, and a pose that only those readings fix (the position
 *        along a corridor from the one sensor seeing its end wall) then moves with them while
 *        explaining every reading. Groups: the readings whose mounting headings lie within
 *        @p group_angle [rad] of one reading's. With W the covariance left without the group
 *        whose loss leaves the largest (determinant) and C that of every reading, returns the
 *        positive part of W / 2 - C: zero where every direction is fixed by two groups alike
 *        (without either the covariance doubles), about W where one group fixes a direction
 *        alone. Plus the same part of every other group with a finite reading @p use leaves out
 *        (a disagreeing reading: a person in front of that sensor, whom its other readings may
 *        explain as a wall at a slant), so that such a group fixes no direction alone even when
 *        losing another group leaves the larger covariance. Positive semi-definite.
 * @param noise_sigma lower bound on the residual standard deviation [m], as in polishPose()
 */
Eigen::Matrix3d oneDirectionLostCovariance(const MapRayCaster& map, const Pose2& pose,
                                           const std::vector<Reading>& readings, const std::vector<bool>& use,
                                           double noise_sigma, double group_angle);

/// Settings of refineSeed().
struct RefinementSettings
{
  double agreement_tolerance = 0.05;      ///< eps [m]
  double robust_scale = 0.1;              ///< Cauchy scale of the first polish [m] (about the seed's error)
  double seed_position_error = 0.1;       ///< how far the seed may be from the optimum in x, y [m]
  double seed_angle_error = 0.05;         ///< ... and in theta [rad]
  double noise_sigma = 0.01;              ///< lower bound on the range noise for the covariance [m]
  int max_iterations = 30;                ///< per polish
  int max_rounds = 3;                     ///< re-polish on the new inlier set at most this often
  int max_escapes = 3;                    ///< leave-one-out rounds to escape a false minimum
  int escape_tries = 4;                   ///< readings tried per leave-one-out round
  int escape_min_inliers = 3;             ///< only candidates with this many inliers try to escape
  int target_inliers = 3;                 ///< below this many inliers, try hypotheses without the
                                          ///< readings most shortened at the seed (obstacle hits)
  int max_dropped_shortened = 3;          ///< ... leaving out at most this many
  int local_search_cells = 0;             ///< below target_inliers, also search (2m+1)^3 poses
                                          ///< around the seed; 0 = no local search
  double local_search_step = 0.05;        ///< lattice step of that search in x, y [m]
  double local_search_angle_step = 0.02;  ///< ... and in theta [rad]
  int multi_start = 0;                    ///< finally, polish again from the (2m+1)^3 - 1 poses of
                                          ///< a lattice around the best pose; 0 = none
  double multi_start_step = 0.05;         ///< lattice step of the multi-start in x, y [m]
  double multi_start_angle_step = 0.02;   ///< ... and in theta [rad]
  /// A leave-one-out round that improves nothing then leaves out pairs of directions (of the
  /// readings it tries, one per direction, each with its parallel readings): two rays crossing
  /// edges between the pose and the optimum.
  bool escape_pairs = false;
  /// With multi_start: run it even from an exact pose, and return every distinct optimum it
  /// reaches with the best one's net consensus (refineSeed()'s @p ties): several exact poses
  /// can share one region (a mirror heading a few cells away).
  bool collect_ties = false;
  /// A prior every polish adds (PosePrior): a tracker's prediction. None by default.
  PosePrior prior;
};

/**
 * @brief From a seed pose and a hypothesis of which readings it explains, the best pose found:
 *        1. annealed robust polishes (Cauchy scale shrinking to eps) on the hypothesis, on the
 *           hypothesis without the readings whose rays pass so close to a map vertex that the
 *           seed's error could put them across an occlusion edge, and, while fewer than
 *           target_inliers readings agree, without the 1, 2, 3 readings most shortened at the
 *           seed (unknown obstacles only shorten readings);
 *        2. optionally a lattice search around the seed (local_search_cells);
 *        3. rounds of verification and plain polish on the eps-inliers while the consensus
 *           improves (more inliers, then lower RMS);
 *        4. leave-one-out re-polishes (the worst reading, the ones passing nearest a vertex) to
 *           escape the false minima that corners create in the piecewise-smooth cost;
 *        5. optionally (multi_start) annealed polishes from @p region_starts (poses spread over
 *           the seed's region) and robust polishes from a lattice of poses around the best one,
 *           on the hypothesis's finite readings, keeping the best (most inliers, then least RMS);
 *           with settings.collect_ties, the other optima tying its net consensus go to @p ties.
 *        Never returns a pose worse than the seed.
 */
Candidate refineSeed(const MapRayCaster& map, const Pose2& seed, const std::vector<Reading>& readings,
                     const std::vector<bool>& hypothesis, const RefinementSettings& settings,
                     const std::vector<Pose2>& region_starts = {}, std::vector<Candidate>* ties = nullptr);

/**
 * @brief widenAlongContinua(), after moving @p candidate to a better place at an end of a
 *        continuum it lies on. Along a corridor, a ray passing a corner can be 2 cm short for
 *        every pose behind the exact place and grow 3 cm per cm beyond it: the exact place is a
 *        few millimetres wide and the polish, with no gradient along the corridor, stops anywhere
 *        on it. At each end of each direction widenAlongContinua() probes where the candidate's
 *        standard deviation (widened) exceeds 3 noise_sigma ([rad] per metre for the heading),
 *        a finite inlier whose residual changes sign between
 *        the candidate and the first pose beyond the end is explained exactly in between: the
 *        crossing (bisected to 0.25 um per 4 m) is polished on the candidate's finite inliers
 *        (settings' eps as the robust scale, noise_sigma, max_iterations). The best such pose
 *        replaces the candidate when it ranks before it (betterCandidate()) by more net readings
 *        or at most half its RMS. Where the candidate ties it within the noise (the same net
 *        consensus, an RMS within noise_sigma of it), the continuum it lay on stays plausible: the
 *        settled pose's covariance adds the candidate's widened one and the move's outer product,
 *        so that noisy readings never turn an honest spread along a corridor into a confident
 *        pose 50 cm from the truth. Along each such direction that is a translation, a pose
 *        explaining more readings (gainAlongContinuum(), within the probed ends: a side sensor
 *        passing a door frame) replaces the candidate when it ranks before it; otherwise an exact
 *        candidate (RMS below 1e-6 m) is never moved.
 */
void settleAlongContinua(const MapRayCaster& map, const std::vector<Reading>& readings,
                         const RefinementSettings& settings, Candidate& candidate);

/**
 * @brief For each reading, how close its ray from @p pose passes to a map vertex, relative to
 *        the pose's uncertainty: min over vertices of (perpendicular distance - t * angle_error),
 *        t being the vertex's distance along the ray [m]. Small values mark readings whose ray may
 *        cross an occlusion edge within the uncertainty (their h is discontinuous there).
 *        +inf for no-return readings and sensors outside free space.
 */
std::vector<double> vertexMargins(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                                  double angle_error);

/**
 * @brief Widens @p candidate's covariance along each direction (x, y, the heading, the walls its
 *        inlier rays hit) in which its pose can move, both ways, while every finite inlier's
 *        residual stays within its value plus @p noise [m]: where that reach R exceeds 3
 *        standard deviations of the covariance along the direction, the variance along it
 *        becomes R^2 / 3 (a uniform spread over [-R, R]). The local derivative of the polish
 *        cannot see a continuum of exact poses (a corridor, parallel walls, a cone facing a flat
 *        wall) when the pose sits at its end; this says so. Reach probed up to 4 m and pi/2.
 */
void widenAlongContinua(const MapRayCaster& map, const std::vector<Reading>& readings, double noise,
                        Candidate& candidate);

/**
 * @brief The pose polished (Levenberg-Marquardt, Cauchy at the settings' eps, noise_sigma,
 *        max_iterations) from @p start on @p candidate's finite inliers, verified, with the
 *        polish's covariance and the candidate's support.
 */
Candidate polishedFrom(const MapRayCaster& map, const std::vector<Reading>& readings,
                       const RefinementSettings& settings, const Candidate& candidate, const Pose2& start);

/**
 * @brief The last polish of the candidates tied at the best net consensus (both engines, after the
 *        region fill), so that each reaches the least residual of its place. First the escapes of
 *        refineSeed() again, leaving out pairs of directions too (escape_pairs): a better pose
 *        within the uniqueness margins replaces the candidate, one beyond them is added as another
 *        candidate. Then polishedFrom() the 26 poses of a lattice around it, half the range
 *        tolerance tau apart in x and y [m] and that over the readings' median finite range in the
 *        heading [rad] (at most a quarter of the uniqueness angle). A better pose
 *        (betterCandidate()) replaces it, its covariance kept; where it lies half a step away or
 *        more, the lattice is laid again around it (three times at most). An exact candidate (RMS
 *        below 1 um) stays, and so does one whose finite inliers' rays pass no vertex within twice
 *        the step (plus the heading step times the reach along the ray and the sensor's offset,
 *        vertexMargins()) and that has no cone reading: the cost is smooth around it. The
 *        piecewise-smooth cost has a basin per set of walls the rays hit, and the seeds'
 *        multi-start lattice is a cell wide: in the paper's floor plan scaled by 0.25, three rays
 *        hit a wall's jog 4 mm in front of the wall they hit from the truth, and the best candidate
 *        stopped 1.15 cm and 0.52 deg from it (RMS 4.2 mm against 0). An exact candidate instead
 *        has its covariance widened to cover the exact places that tie it within the uniqueness
 *        margins (absorbTiedDuplicates()), polished from a lattice four steps wide around it (near
 *        such an edge) and from lattices at half and all of the margins; one beyond them is
 *        another candidate: two exact places 4.8 cm and 2.5 deg apart, 3.1 deg apart where a
 *        cone's edge sweeps a wall, 3.9 cm and 4.6 deg, and the engine found the one the readings
 *        did not come from (verification seeds 815, 812, 883). Last, the heading mirrored about
 *        the walls where most finite inlier rays meet theirs at one angle alpha to the normal
 *        (turned by -2 alpha) is polished: a twin tying the candidate widens its covariance within
 *        the margins and is another candidate beyond them (seed 881: rays square to a warehouse's
 *        walls read the same at +-1.85 deg). The candidates are ranked and de-duplicated again.
 * @param options range_tolerance, the uniqueness margins, max_candidates and threads
 * @param settings the polish's eps, noise_sigma and max_iterations
 * @param candidates ranked (rankAndDeduplicate()), the best first
 */
void settleInNearBasins(const MapRayCaster& map, const std::vector<Reading>& readings, const LocalizerOptions& options,
                        const RefinementSettings& settings, std::vector<Candidate>& candidates);

/// A candidate at @p pose with the agreement @p eval (inliers, contradicted, RMS); no covariance.
Candidate candidateFrom(const Pose2& pose, const PoseEvaluation& eval);

/// A candidate at @p pose, verified but not polished.
Candidate verifiedCandidate(const MapRayCaster& map, const Pose2& pose, const std::vector<Reading>& readings,
                            double eps);

}  // namespace core
}  // namespace fdml_localization
