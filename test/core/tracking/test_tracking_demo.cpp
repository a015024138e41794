// The demo's relocalizations (make demo: config/scenarios/demo.yaml, launch/simulation.launch
// with config/localizer.yaml), replayed ROS-free and without their timing
// (relocalization_replay.h).
#include "localizer_test_utils.h"
#include "relocalization_replay.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <algorithm>
#include <utility>

namespace core = fdml_localization::core;

TEST(HypothesisTrackerDemo, KidnapsAmongPeopleAndChairsAreNeverAnsweredWrong)
{
  // Without a confirming search (~confirm_searches 0) each of these runs answered one kidnap
  // wrong, one search having returned a single place alike: at seed 22 the 48th kidnap, to
  // (11.15, 2.51), was answered 5.6 m away at the map's mirrored place, which explained 8 of
  // the 10 readings (three on people and chairs) while the truth explained 7. The later search
  // brings the true place to compete.
  const auto map = core::test::loadMap("maps/apartment.poly");
  const core::LocalizerOptions search = fdml_test::globalSearchOptions(120, 0.03);  // the demo's launch
  core::TrackerOptions o;                                                           // config/localizer.yaml's
  o.range_tolerance = search.range_tolerance;
  o.agreement_tolerance = search.agreement_tolerance;
  o.fix_covariance_scale = 10.0;  // k / stride, as the node sets it
  const std::pair<std::uint64_t, int> runs[] = { { 18, 53 }, { 22, 49 }, { 25, 51 }, { 39, 59 } };
  int answered = 0, kidnaps = 0;
  for (const auto& run : runs)
  {
    const fdml_test::ReplayAnswers answers =
        fdml_test::replayKidnaps(fdml_test::demoScenario(run.first), map, 10, 1, o, search, run.second, 30.0);
    EXPECT_EQ(answers.wrong, 0) << "seed " << run.first << ": " << answers.first_wrong;
    answered += answers.right + answers.wrong;
    kidnaps += run.second;
    std::printf("seed %llu: %d kidnaps, %d right, %d wrong, %d unanswered, %.2f s to the answer on average\n",
                static_cast<unsigned long long>(run.first), run.second, answers.right, answers.wrong,
                answers.unanswered, answers.seconds / std::max(1, answers.right + answers.wrong));
  }
  EXPECT_GE(answered, kidnaps - 2);
}
