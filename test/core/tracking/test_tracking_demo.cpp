// The demo's relocalizations (make demo: config/scenarios/demo.yaml, launch/simulation.launch
// with config/localizer.yaml) and the patrol's (apartment_patrol.yaml, tracking_patrol.test),
// replayed ROS-free and without their timing (relocalization_replay.h).
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
  const core::TrackerOptions o = fdml_test::launchTrackerOptions(core::TrackerOptions(), search, false);
  const std::pair<std::uint64_t, int> runs[] = { { 18, 53 }, { 22, 49 }, { 25, 51 }, { 39, 59 } };
  int answered = 0, kidnaps = 0;
  for (const auto& run : runs)
  {
    const fdml_test::ReplayAnswers answers =
        fdml_test::replayKidnaps(fdml_test::demoScenario(run.first), map, 10, 1, o, search, run.second, {});
    EXPECT_EQ(answers.wrong, 0) << "seed " << run.first << ": " << answers.first_wrong;
    answered += answers.right + answers.wrong;
    kidnaps += run.second;
    std::printf("seed %llu: %d kidnaps, %d right, %d wrong, %d unanswered, %.2f s to the answer on average\n",
                static_cast<unsigned long long>(run.first), run.second, answers.right, answers.wrong,
                answers.unanswered, answers.seconds / std::max(1, answers.right + answers.wrong));
  }
  EXPECT_GE(answered, kidnaps - 2);
}

TEST(HypothesisTrackerPatrol, AnAnswerOnlyJustReachingKPrimeIsSearchedAroundMoreWidely)
{
  // Driving among five people, seed 14's 21st kidnap was answered at 123.2 s 9.5 cm and 12 deg
  // off, and the wrong pose stayed published for 43 of the next 5 s's updates: its fixes only just
  // reached k' (people read as walls at a slant), and the box around it (3 sigma of a precision
  // earned on them, at least 2.9 deg) never reached the truth, which explains more readings.
  // Such a hypothesis's box now reaches at least 3 times the smallest in heading, 2 in position.
  const auto map = core::test::loadMap("maps/apartment.poly");
  const core::LocalizerOptions search = fdml_test::globalSearchOptions(120, 0.03);
  const core::TrackerOptions o = fdml_test::launchTrackerOptions(core::TrackerOptions(), search, true);
  core::ScenarioConfig patrol = fdml_test::apartmentPatrol(5);
  patrol.seed = 14;
  const fdml_test::ReplayAnswers answers = fdml_test::replayKidnaps(patrol, map, 10, 2, o, search, 21, { 30.0, 5.0 });
  EXPECT_EQ(answers.wrong, 0) << answers.first_wrong;
  EXPECT_EQ(answers.followed_wrong, 0);
  EXPECT_EQ(answers.right, 21);
  EXPECT_GT(answers.followed_published, 1800);  // of 21 x 5 s at 20 updates per second
}
