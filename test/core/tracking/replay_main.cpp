// Relocalizations replayed ROS-free (relocalization_replay.h): the fraction of kidnaps the
// node's relocalization answers right, wrong or not at all, and the time to the answer, over
// many scenario seeds. Prints a line per seed and a summary; exits 1 when any answer (or, with
// --follow or --window, any update after one) was wrong,
// 2 on a bad flag.
//   replay_relocalizations [--scenario demo|patrol] [--seeds FIRST:LAST] [--kidnaps N]
//                          [--confirm N] [--min-support S] [--timeout SECONDS] [--follow SECONDS]
//                          [--window SECONDS]
// demo: config/scenarios/demo.yaml (turning in place, four cones at 1.6 Hz, three people, two
// chairs; k = 10, stride 1, as make demo runs it). patrol: config/scenarios/apartment_patrol.yaml
// (driving, four rays at 10 Hz, five people; k = 10, stride 2 and the odometry noise of
// tracking_patrol.test). Both on maps/apartment.poly, the tracker at config/localizer.yaml's
// settings with range_tolerance 0.03 m (the launches'); --confirm and --min-support override
// confirm_searches and min_support. --follow S keeps tracking S seconds after each answer and
// counts the updates that publish a pose and the wrong ones among them (a wrong answer that
// persists). --window S instead runs every kidnap exactly S seconds (the answer within them,
// followed to their end): the kidnaps and the people then do not depend on when the answers
// came, so two builds are compared kidnap by kidnap.
#include "localizer_test_utils.h"
#include "relocalization_replay.h"

#include "fdml_localization/core/util/text_parsing.h"

#include <cstdio>
#include <cstring>
#include <iostream>
#include <stdexcept>
#include <string>

namespace
{
namespace core = fdml_localization::core;

struct Args
{
  bool patrol = false;
  int first_seed = 1, last_seed = 10, kidnaps = 100;
  fdml_test::ReplayTiming timing;
  core::TrackerOptions tracker;
};

/// Seconds [s] of @p flag: @p value in (0, @p high], or [0, @p high] when @p zero_allowed
/// (@p range says which); @throws std::invalid_argument naming the flag.
double seconds(const std::string& flag, const std::string& value, bool zero_allowed, double high, const char* range)
{
  const double s = core::parseNumber(value, flag);
  if (!((zero_allowed ? s >= 0.0 : s > 0.0) && s <= high))
  {
    throw std::invalid_argument(flag + " needs " + range + " s, got '" + value + "'");
  }
  return s;
}

/// Applies a timing flag (--timeout, --follow, --window); false for another flag.
bool applyTiming(const std::string& flag, const std::string& value, fdml_test::ReplayTiming& timing)
{
  if (flag == "--timeout")
  {
    timing.timeout = seconds(flag, value, false, 3600.0, "(0, 3600]");
  }
  else if (flag == "--follow")
  {
    timing.follow = seconds(flag, value, true, 600.0, "[0, 600]");
  }
  else if (flag == "--window")
  {
    timing.window = seconds(flag, value, false, 3600.0, "(0, 3600]");
  }
  return flag == "--timeout" || flag == "--follow" || flag == "--window";
}

/// Applies one flag; @throws std::invalid_argument naming it.
void apply(const std::string& flag, const std::string& value, Args& args)
{
  if (flag == "--scenario" && (value == "demo" || value == "patrol"))
  {
    args.patrol = value == "patrol";
  }
  else if (flag == "--seeds" && value.find(':') != std::string::npos)
  {
    const std::size_t colon = value.find(':');
    args.first_seed = core::parseInteger(value.substr(0, colon), "--seeds FIRST");
    args.last_seed = core::parseInteger(value.substr(colon + 1), "--seeds LAST");
    if (args.first_seed < 1 || args.last_seed < args.first_seed || args.last_seed - args.first_seed >= 100000)
    {
      throw std::invalid_argument("--seeds needs 1 <= FIRST <= LAST < FIRST + 100000, got '" + value + "'");
    }
  }
  else if (flag == "--kidnaps")
  {
    args.kidnaps = core::parseInteger(value, "--kidnaps");
    if (args.kidnaps < 1 || args.kidnaps > 100000)
    {
      throw std::invalid_argument("--kidnaps needs 1 to 100000, got '" + value + "'");
    }
  }
  else if (flag == "--confirm")
  {
    args.tracker.confirm_searches = core::parseInteger(value, "--confirm");
  }
  else if (flag == "--min-support")
  {
    args.tracker.min_support = core::parseNumber(value, "--min-support");
  }
  else if (!applyTiming(flag, value, args.timing))
  {
    throw std::invalid_argument("unknown flag or value: " + flag + " " + value +
                                " (flags: --scenario demo|patrol, --seeds FIRST:LAST, --kidnaps N, --confirm N, "
                                "--min-support S, --timeout SECONDS, --follow SECONDS, --window SECONDS)");
  }
}

/// The replay of @p args for one scenario seed.
fdml_test::ReplayAnswers replaySeed(const Args& args, const std::shared_ptr<const core::MapRayCaster>& map, int seed)
{
  const core::LocalizerOptions search = fdml_test::globalSearchOptions(120, 0.03);
  const core::TrackerOptions o = fdml_test::launchTrackerOptions(args.tracker, search, args.patrol);
  core::ScenarioConfig scenario = args.patrol ? fdml_test::apartmentPatrol(5) : fdml_test::demoScenario(seed);
  scenario.seed = static_cast<std::uint64_t>(seed);
  const int stride = args.patrol ? 2 : 1;
  return fdml_test::replayKidnaps(scenario, map, 10, stride, o, search, args.kidnaps, args.timing);
}
/// The summary lines of the replay of @p args.
void printTotal(const Args& args, const fdml_test::ReplayAnswers& total)
{
  const int answered = total.right + total.wrong;
  std::printf("%s, seeds %d to %d, %d kidnaps each: right %d, wrong %d, unanswered %d; mean time to the answer "
              "%.2f s\n",
              args.patrol ? "patrol" : "demo", args.first_seed, args.last_seed, args.kidnaps, total.right, total.wrong,
              total.unanswered, answered > 0 ? total.seconds / answered : 0.0);
  if (args.timing.following())
  {
    const bool window = args.timing.window > 0.0;
    std::printf("followed %s%.1f s%s: %d updates published a pose, %d of them wrong (%.2f %%)\n",
                window ? "to the end of each kidnap's " : "", window ? args.timing.window : args.timing.follow,
                window ? "" : " after each answer", total.followed_published, total.followed_wrong,
                total.followed_published > 0 ? 100.0 * total.followed_wrong / total.followed_published : 0.0);
  }
}
}  // namespace

int main(int argc, char** argv)
{
  Args args;
  try
  {
    for (int i = 1; i < argc; i += 2)
    {
      apply(argv[i], i + 1 < argc ? argv[i + 1] : "", args);
    }
    const std::vector<std::string> errors = core::validate(args.tracker);
    if (!errors.empty())
    {
      throw std::invalid_argument(errors.front());
    }
  }
  catch (const std::invalid_argument& e)
  {
    std::cerr << "replay_relocalizations: " << e.what() << "\n";
    return 2;
  }
  const auto map = core::test::loadMap("maps/apartment.poly");
  fdml_test::ReplayAnswers total;
  for (int seed = args.first_seed; seed <= args.last_seed; ++seed)
  {
    fdml_test::ReplayAnswers a;
    try
    {
      a = replaySeed(args, map, seed);
    }
    catch (const std::exception& e)
    {
      std::cerr << "replay_relocalizations: seed " << seed << ": " << e.what() << "\n";
      return 2;
    }
    std::printf("seed %d: right %d wrong %d unanswered %d", seed, a.right, a.wrong, a.unanswered);
    if (args.timing.following())
    {
      std::printf("; followed: published %d wrong %d", a.followed_published, a.followed_wrong);
    }
    std::printf("%s%s\n", a.first_wrong.empty() ? "" : "; ", a.first_wrong.c_str());
    total.right += a.right;
    total.wrong += a.wrong;
    total.unanswered += a.unanswered;
    total.seconds += a.seconds;
    total.followed_published += a.followed_published;
    total.followed_wrong += a.followed_wrong;
  }
  printTotal(args, total);
  return total.wrong > 0 || total.followed_wrong > 0 ? 1 : 0;
}
