// The fast part of the verification suite (issue 16; the whole run is `make verify`): random
// trials over reading geometries on small maps, both engines; the truth among the candidates in
// every noise-free trial (both engines) and no certificate contradicted by the reference.
#include "verification_trials.h"

#include <gtest/gtest.h>

namespace fdml_localization
{
namespace core
{
namespace
{
class Verification : public ::testing::TestWithParam<Engine>
{};

TEST_P(Verification, RandomTrialsNeverMissTheTruthNorContradictACertificate)
{
  const auto maps = verification::smallMaps();
  const std::vector<std::unique_ptr<Localizer>> localizers = verification::smallMapLocalizers(GetParam());
  std::mt19937_64 rng(1600);
  verification::Figures figures;
  for (int t = 0; t < 40; ++t)
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
  std::printf("%s: %d trials (%d noise-free), %d complete certificates, top-1 %d\n", toString(GetParam()),
              figures.trials, figures.noise_free, figures.complete, figures.top1);
}

INSTANTIATE_TEST_SUITE_P(Engines, Verification, ::testing::Values(Engine::Voxel, Engine::Adaptive),
                         [](const ::testing::TestParamInfo<Engine>& info) {
                           return std::string(toString(info.param));
                         });

}  // namespace
}  // namespace core
}  // namespace fdml_localization
