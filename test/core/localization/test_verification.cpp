// The fast part of the verification suite (issue 16; the whole run is `make verify`): random
// trials over reading geometries on small maps and on generated ones, both engines; the truth among the candidates in
// every noise-free trial (both engines) and no certificate contradicted by the reference.
#include "generated_maps.h"
#include "verification_checks.h"

#include <gtest/gtest.h>

namespace fdml_localization
{
namespace core
{
namespace
{
class Verification : public ::testing::TestWithParam<Engine>
{};

/// @p trials random trials (seed @p seed) on @p maps: each failure, the truth missed in no
/// noise-free trial, no certificate contradicted, no best candidate inaccurate.
void expectNoFailure(const std::vector<std::shared_ptr<const MapRayCaster>>& maps, Engine engine, int trials,
                     std::uint64_t seed)
{
  const std::vector<std::unique_ptr<Localizer>> localizers = verification::localizersFor(maps, engine);
  std::mt19937_64 rng(seed);
  verification::Figures figures;
  for (int t = 0; t < trials; ++t)
  {
    const verification::Trial trial = verification::makeTrial(maps, rng);
    verification::runTrial(*localizers[static_cast<std::size_t>(trial.map)], trial, 300, rng, figures);
  }
  for (const std::string& failure : figures.failures)
  {
    ADD_FAILURE() << failure;
  }
  EXPECT_EQ(figures.missed, 0) << "of " << figures.noise_free << " noise-free trials";
  EXPECT_EQ(figures.contradicted, 0) << "of " << figures.trials << " trials";
  EXPECT_EQ(figures.inaccurate, 0) << "of " << figures.noise_free << " noise-free trials";
  std::printf("%s: %d trials (%d noise-free), %d complete certificates, top-1 %d\n", toString(engine), figures.trials,
              figures.noise_free, figures.complete, figures.top1);
}

TEST_P(Verification, RandomTrialsNeverMissTheTruthNorContradictACertificate)
{
  expectNoFailure(verification::smallMaps(), GetParam(), 40, 1600);
}

// Maps no test was tuned on (generated_maps.h): a random 70-gon (walls at any angle), a
// generated 12 x 9 m building off the bundled maps' 5 cm raster (1.2 m corridors, 3 m rooms,
// 80 cm doors) and a furnished 8 x 6 m room turned by a random angle (rotated boxes, round
// pillars); `verify_localization --random-maps N --buildings N --rooms N` runs many more.
TEST_P(Verification, GeneratedMapsNeverMissTheTruthNorContradictACertificate)
{
  std::vector<std::shared_ptr<const MapRayCaster>> maps;
  for (verification::GeneratedMap& generated : verification::generatedMaps(1, 1, 1601, 1))
  {
    maps.push_back(std::move(generated.map));
  }
  expectNoFailure(maps, GetParam(), 40, 1601);
}

INSTANTIATE_TEST_SUITE_P(Engines, Verification, ::testing::Values(Engine::Voxel, Engine::Adaptive),
                         [](const ::testing::TestParamInfo<Engine>& info) {
                           return std::string(toString(info.param));
                         });

}  // namespace
}  // namespace core
}  // namespace fdml_localization
