// The merge of polished candidates (ranking.h): rankAndAbsorbDuplicates() keeps what
// rankAndDeduplicate() keeps, and a tie it drops lies within 3 standard deviations of the one
// kept near it; a duplicate that does not tie leaves the covariance alone.
#include "fdml_localization/core/localization/ranking.h"

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
Candidate exactCandidate(const Pose2& pose, int inliers, double rms, double sd_xy, double sd_theta)
{
  Candidate c;
  c.pose = pose;
  c.inliers = inliers;
  c.rms_residual = rms;
  c.covariance = Eigen::Vector3d(sd_xy * sd_xy, sd_xy * sd_xy, sd_theta * sd_theta).asDiagonal();
  return c;
}

double mahalanobis2(const Candidate& kept, const Pose2& other)
{
  const Eigen::Vector3d d = poseDifference(other, kept.pose);
  return d.dot(kept.covariance.ldlt().solve(d));
}

TEST(RankAndAbsorbDuplicates, ATieDroppedAsADuplicateLiesWithinTheKeptCovariance)
{
  // Random pairs of exact places within the uniqueness margins (0.1 m, 0.1 rad), their RMS
  // apart by rounding: one is kept, and it covers the other; a third candidate far away is kept
  // unchanged, and the kept poses are rankAndDeduplicate()'s.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> offset(-0.07, 0.07), rms(0.0, 1e-12);
  for (int trial = 0; trial < 500; ++trial)
  {
    const Pose2 a(1.0, 2.0, 0.5);
    const Pose2 b(a.x + offset(rng), a.y + offset(rng), a.theta + offset(rng));
    const std::vector<Candidate> all{ exactCandidate(a, 4, rms(rng), 0.007, 0.005),
                                      exactCandidate(b, 4, rms(rng), 0.007, 0.005),
                                      exactCandidate(Pose2(5.0, 2.0, 0.5), 4, 0.0, 0.01, 0.01) };
    const std::vector<Candidate> merged = rankAndAbsorbDuplicates(all, 0.1, 0.1, 1e-3, 10);
    const std::vector<Candidate> plain = rankAndDeduplicate(all, 0.1, 0.1, 10);
    ASSERT_EQ(merged.size(), 2u);
    ASSERT_EQ(plain.size(), 2u);
    for (std::size_t i = 0; i < merged.size(); ++i)
    {
      EXPECT_EQ(poseDifference(merged[i].pose, plain[i].pose).norm(), 0.0);
    }
    const Candidate& near = merged[0].pose.x < 3.0 ? merged[0] : merged[1];
    const Candidate& far = merged[0].pose.x < 3.0 ? merged[1] : merged[0];
    EXPECT_LE(mahalanobis2(near, a), 9.0) << "trial " << trial;
    EXPECT_LE(mahalanobis2(near, b), 9.0) << "trial " << trial;
    EXPECT_DOUBLE_EQ(far.covariance(0, 0), 1e-4);
  }
}

TEST(RankAndAbsorbDuplicates, ADuplicateThatDoesNotTieLeavesTheCovarianceAlone)
{
  // The dropped one explains a reading fewer, or its RMS exceeds the kept one's by more than the
  // noise: the kept candidate's covariance stays as it was, and the dropped pose lies outside it.
  const Candidate kept = exactCandidate(Pose2(0.0, 0.0, 0.0), 5, 0.0, 0.005, 0.005);
  for (const Candidate& dropped : { exactCandidate(Pose2(0.06, 0.0, 0.05), 4, 0.0, 0.005, 0.005),
                                    exactCandidate(Pose2(0.06, 0.0, 0.05), 5, 0.01, 0.005, 0.005) })
  {
    const std::vector<Candidate> merged = rankAndAbsorbDuplicates({ kept, dropped }, 0.1, 0.1, 1e-3, 10);
    ASSERT_EQ(merged.size(), 1u);
    EXPECT_EQ(merged[0].covariance, kept.covariance);
    EXPECT_GT(mahalanobis2(merged[0], dropped.pose), 9.0);
  }
}

TEST(ExactTie, ExactPlacesOfTheSameConsensusTieWhateverTheirRounding)
{
  const Candidate a = exactCandidate(Pose2(), 5, 1.9e-16, 0.01, 0.01);
  EXPECT_TRUE(exactTie(a, exactCandidate(Pose2(1.0, 0.0, 0.0), 5, 3.2e-16, 0.01, 0.01)));
  EXPECT_TRUE(betterCandidate(a, exactCandidate(Pose2(), 5, 3.2e-16, 0.01, 0.01)));  // ranked by rounding
  EXPECT_FALSE(exactTie(a, exactCandidate(Pose2(), 4, 0.0, 0.01, 0.01)));
  EXPECT_FALSE(exactTie(a, exactCandidate(Pose2(), 5, 2e-6, 0.01, 0.01)));
  Candidate contradicted = exactCandidate(Pose2(), 6, 0.0, 0.01, 0.01);
  contradicted.contradicted = 1;
  EXPECT_FALSE(exactTie(a, contradicted));  // the same net consensus, one reading contradicted
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
