// Issue 16's reproduction: four range sensors (front, left, back, right, 0.15 m from the
// centre) on a robot driving 1 cm between readings, k = 20, noise-free, no obstacles, in the
// apartment and the office. The truth explains every reading exactly, so it must be among the
// candidates (5 cm, 2 deg) in every trial, with either engine, and the best candidate, when it
// is the truth's, must lie within 1 cm and 0.5 deg of it.
#include "fdml_localization/core/localization/certificate.h"
#include "fdml_localization/core/localization/localizer.h"
#include "fdml_localization/core/localization/robust_search.h"

#include "verification_checks.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
using test::angleError;
using test::positionError;

constexpr double kDeg = kPi / 180.0;

/// Reading i comes from sensor i mod 4 after the robot drove i cm straight ahead.
std::vector<Pose2> fourSensorDrivingOffsets(int k)
{
  const Pose2 mounts[4] = { Pose2(0.15, 0.0, 0.0), Pose2(0.0, 0.15, 0.5 * kPi), Pose2(-0.15, 0.0, kPi),
                            Pose2(0.0, -0.15, -0.5 * kPi) };
  std::vector<Pose2> offsets;
  for (int i = 0; i < k; ++i)
  {
    offsets.push_back(compose(Pose2(0.01 * i, 0.0, 0.0), mounts[i % 4]));
  }
  return offsets;
}

/// A random pose whose whole path (every sensor position) is in free space, 0.1 m from walls.
Pose2 drivingPose(const MapRayCaster& map, const std::vector<Pose2>& offsets, std::mt19937_64& rng)
{
  for (;;)
  {
    const Pose2 truth = test::randomFreePose(map, rng, 0.25);
    bool clear = true;
    for (const Pose2& g : offsets)
    {
      const Vec2 p = compose(truth, g).position();
      clear = clear && map.isFree(p) && test::clearance2(map, p) > 0.01;
    }
    if (clear)
    {
      return truth;
    }
  }
}

/// True when @p candidate explains every reading exactly and lies from @p truth along the
/// undetermined direction @p null, with its covariance saying so (the truth within 3 standard
/// deviations along it).
bool onContinuum(const Candidate& candidate, const Pose2& truth, const Eigen::Vector3d& null, int k)
{
  if (null.isZero() || candidate.inliers < k || candidate.rms_residual > 1e-6)
  {
    return false;
  }
  const Eigen::Vector3d d(candidate.pose.x - truth.x, candidate.pose.y - truth.y,
                          angleDiff(candidate.pose.theta, truth.theta));
  const Eigen::Vector3d across = d - d.dot(null) * null;
  const double along = d.dot(null);
  return across.head<2>().norm() < 0.01 && std::abs(across(2)) < 0.5 * kDeg &&
         along * along <= 9.0 * null.dot(candidate.covariance * null);
}

struct MissCount
{
  int trials = 0;
  int missed = 0;        ///< no candidate within 5 cm and 2 deg
  int inaccurate = 0;    ///< the best candidate is the truth's but beyond 1 cm or 0.5 deg
  int contradicted = 0;  ///< certificates the truth contradicts
  int complete = 0;      ///< complete certificates
  int excluded = 0;      ///< regions at the bound proved empty
  int regions = 0;       ///< regions at the bound
};

MissCount runDriving(const std::string& map_file, Engine engine, int trials, std::uint64_t seed)
{
  const auto map = test::loadMap(map_file);
  LocalizerOptions options;
  options.engine = engine;
  Localizer localizer(map, options);
  const std::vector<Pose2> offsets = fourSensorDrivingOffsets(20);
  std::mt19937_64 rng(seed);
  MissCount count;
  for (int trial = 0; trial < trials; ++trial)
  {
    const Pose2 truth = drivingPose(*map, offsets, rng);
    const std::vector<Reading> readings = test::exactReadings(*map, truth, offsets);
    const Result result = localizer.localize(readings);
    ++count.trials;
    // The truth explains every reading: no bound below that holds, and a complete certificate
    // claims every pose reaching the bound lies in a candidate's region (the truth's too).
    const Certificate& certificate = result.certificate;
    count.complete += certificate.complete ? 1 : 0;
    count.excluded += certificate.regions_excluded;
    count.regions += certificate.regions_at_bound;
    if (certificate.max_consensus_bound < consensusWithin(*map, truth, readings, options.range_tolerance))
    {
      ++count.contradicted;
    }
    const Eigen::Vector3d null = verification::undeterminedDirection(*map, truth, readings);
    if (std::any_of(result.candidates.begin(), result.candidates.end(),
                    [&](const Candidate& c) { return onContinuum(c, truth, null, 20); }))
    {
      continue;  // the readings do not determine the pose, and the candidate says so
    }
    const Candidate* nearest = test::nearestCandidate(result, truth);
    const bool found =
        nearest && positionError(nearest->pose, truth) < 0.05 && angleError(nearest->pose, truth) < 2.0 * kDeg;
    if (!found)
    {
      ++count.missed;
      const Candidate& best = result.candidates.empty() ? Candidate() : result.candidates[0];
      std::printf("%s %s: missed (%.6f, %.6f, %.6f) null (%.2f %.2f %.2f); %zu candidates, best %d inliers rms %.4f "
                  "at (%.3f, %.3f, %.4f) cov %g %g %g\n",
                  map_file.c_str(), toString(engine), truth.x, truth.y, truth.theta, null(0), null(1), null(2),
                  result.candidates.size(), best.inliers, best.rms_residual, best.pose.x, best.pose.y, best.pose.theta,
                  best.covariance(0, 0), best.covariance(1, 1), best.covariance(2, 2));
      continue;
    }
    if (nearest == &result.candidates[0] &&
        (positionError(nearest->pose, truth) > 0.01 || angleError(nearest->pose, truth) > 0.5 * kDeg))
    {
      ++count.inaccurate;
      std::printf("%s %s: inaccurate at (%.6f, %.6f, %.6f): %.1f cm %.2f deg rms %.4f cov %g %g %g\n", map_file.c_str(),
                  toString(engine), truth.x, truth.y, truth.theta, 100 * positionError(nearest->pose, truth),
                  angleError(nearest->pose, truth) / kDeg, nearest->rms_residual, nearest->covariance(0, 0),
                  nearest->covariance(1, 1), nearest->covariance(2, 2));
    }
  }
  return count;
}

class NeverMiss : public ::testing::TestWithParam<std::tuple<std::string, Engine>>
{};

TEST_P(NeverMiss, FourSensorsDriving)
{
  const MissCount count = runDriving(std::get<0>(GetParam()), std::get<1>(GetParam()), 20, 16);
  EXPECT_EQ(count.missed, 0) << "of " << count.trials;
  EXPECT_EQ(count.inaccurate, 0) << "of " << count.trials;
  EXPECT_EQ(count.contradicted, 0) << "of " << count.trials;
  std::printf("complete certificates: %d of %d; regions at the bound %d, %d of them excluded\n", count.complete,
              count.trials, count.regions, count.excluded);
}

INSTANTIATE_TEST_SUITE_P(Maps, NeverMiss,
                         ::testing::Combine(::testing::Values("maps/apartment.poly", "maps/office.poly"),
                                            ::testing::Values(Engine::Voxel, Engine::Adaptive)));

}  // namespace
}  // namespace core
}  // namespace fdml_localization
