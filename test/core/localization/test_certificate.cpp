// The voxel engine's certificate where its bound is not attained (certifyVoxels() then counts
// the regions at the bound and those holding a candidate from bit masks): against
// connectedComponents() and the voxel boxes holding each candidate's pose, on random count
// fields, with candidates inside voxels, on their faces and corners, at the heading's wrap and
// outside the grid.
#include "fdml_localization/core/localization/certificate.h"

#include "fdml_localization/core/localization/adaptive/leaf_clustering.h"
#include "fdml_localization/core/localization/components.h"

#include "localizer_test_utils.h"

#include <gtest/gtest.h>

#include <random>

namespace fdml_localization
{
namespace core
{
namespace
{
/// Regions of @p clusters holding a candidate's pose in one of their voxel boxes.
int coveredRegions(const GridSpec& spec, const std::vector<VoxelCluster>& clusters,
                   const std::vector<Candidate>& candidates)
{
  int covered = 0;
  for (const VoxelCluster& cluster : clusters)
  {
    bool holds = false;
    for (std::size_t v : cluster.voxels)
    {
      for (const Candidate& c : candidates)
      {
        holds = holds || voxelBox(spec, v).contains(c.pose);
      }
    }
    covered += holds ? 1 : 0;
  }
  return covered;
}

/// A candidate at a random pose of @p spec's grid; on a voxel's face, edge or corner for @p
/// border 1 to 3 (x, then y, then theta on a cell boundary).
Candidate candidateIn(const GridSpec& spec, std::mt19937_64& rng, int border)
{
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int ix = static_cast<int>(rng() % static_cast<unsigned>(spec.nx + 1));
  const int iy = static_cast<int>(rng() % static_cast<unsigned>(spec.ny + 1));
  const int it = static_cast<int>(rng() % static_cast<unsigned>(spec.nt + 1));
  Candidate c;
  c.pose.x = spec.origin_x + (ix + (border >= 1 ? 0.0 : unit(rng))) * spec.cell;
  c.pose.y = spec.origin_y + (iy + (border >= 2 ? 0.0 : unit(rng))) * spec.cell;
  c.pose.theta = -kPi + (it + (border >= 3 ? 0.0 : unit(rng))) * spec.thetaStep();
  return c;
}

TEST(CertifyVoxels, UnattainedBoundCountsRegionsAsTheComponentsAndBoxes)
{
  const auto map = test::lRoomMap();
  // Three readings: no pose explains more, while the field's maximum (the bound) is 5.
  std::vector<Reading> readings(3);
  for (std::size_t i = 0; i < readings.size(); ++i)
  {
    readings[i].range = 1.0 + 0.5 * static_cast<double>(i);
    readings[i].offset.theta = 2.0 * static_cast<double>(i);
  }
  std::mt19937_64 rng(31);
  int covered_seen = 0;
  for (const GridSpec& spec : { test::smallSpec(23, 11, 9), test::smallSpec(70, 5, 2), test::smallSpec(9, 7, 1) })
  {
    for (int trial = 0; trial < 20; ++trial)
    {
      std::vector<std::uint8_t> count(spec.voxelCount());
      for (std::uint8_t& c : count)
      {
        c = static_cast<std::uint8_t>(rng() % 6);
      }
      Result result;
      for (int j = 0; j < 6; ++j)
      {
        result.candidates.push_back(candidateIn(spec, rng, j % 4));
      }
      result.candidates.back().pose.x = spec.origin_x - 1.0;  // outside the grid
      certifyVoxels(*map, readings, 0.05, spec, count, result);
      const std::vector<VoxelCluster> clusters = connectedComponents(spec, count, 5);
      const Certificate& c = result.certificate;
      EXPECT_EQ(c.max_consensus_bound, 5);
      EXPECT_EQ(c.best_consensus, consensusWithin(*map, result.candidates.front().pose, readings, 0.05));
      EXPECT_EQ(c.regions_at_bound, static_cast<int>(clusters.size()));
      EXPECT_EQ(c.regions_covered, coveredRegions(spec, clusters, result.candidates));
      EXPECT_EQ(c.regions_excluded, 0);
      EXPECT_FALSE(c.complete);
      covered_seen += c.regions_covered;
    }
  }
  EXPECT_GT(covered_seen, 60);  // most candidates lie in a region (several on borders of two)
}

}  // namespace
}  // namespace core
}  // namespace fdml_localization
