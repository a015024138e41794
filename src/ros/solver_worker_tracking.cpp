// The worker's handling of sensor batches: a pose hint, a global search or a tracking update per
// batch, then the publishing rule (docs/localizer_node.md#tracking).
#include "fdml_localization/ros/solver_worker.h"

#include "fdml_localization/core/util/stopwatch.h"
#include "fdml_localization/ros/conversions.h"

#include <ros/ros.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>

namespace fdml_localization
{
namespace
{
std::uint8_t statusOf(core::TrackState state)
{
  switch (state)
  {
    case core::TrackState::Tracking:
      return fdml_localization::Status::TRACKING;
    case core::TrackState::Ambiguous:
      return fdml_localization::Status::AMBIGUOUS;
    default:
      return fdml_localization::Status::LOST;
  }
}

std::string describeTracking(const core::HypothesisTracker& tracker, int k)
{
  const std::vector<core::Hypothesis>& hypotheses = tracker.hypotheses();
  char text[256];
  if (hypotheses.empty())
  {
    return "no hypothesis";
  }
  const core::Hypothesis& best = hypotheses.front();
  const double second = hypotheses.size() > 1 ? hypotheses[1].support : 0.0;
  std::snprintf(text, sizeof(text),
                "%s: %zu hypothes%s, best support %.2f (next %.2f), its last fix explains %d of %d readings, "
                "%d update(s) missed",
                core::toString(tracker.state()), hypotheses.size(), hypotheses.size() == 1 ? "is" : "es", best.support,
                second, best.last_fix.inliers, k, best.misses);
  return text;
}

/// One line per hypothesis for the "tracking" debug logger (rosconsole
/// ros.fdml_localization.tracking): where each stands, its support and how sure it is.
void traceHypotheses(const core::HypothesisTracker& tracker, const Job& job)
{
  for (const core::Hypothesis& h : tracker.hypotheses())
  {
    const core::Pose2 p = core::compose(h.map_to_odom, job.batch.base_newest);
    ROS_DEBUG_NAMED("tracking",
                    "t %.2f hypothesis %llu: (%.3f, %.3f, %.3f) support %.2f, %d fixes, %d missed, last fix %d "
                    "inliers, 3 sigma %.3f m %.3f rad%s",
                    stampToTime(job.batch.newest_stamp).toSec(), static_cast<unsigned long long>(h.id), p.x, p.y,
                    p.theta, h.support, h.fixes, h.misses, h.last_fix.inliers, core::positionSigma3(h.covariance),
                    core::headingSigma3(h.covariance), h.conflicted ? ", conflicted" : "");
  }
}
}  // namespace

SolverWorker::Directive SolverWorker::takeDirective(const Job& job)
{
  Directive d;
  std::lock_guard<std::mutex> lock(state_.mutex);
  d.stale = job.generation != state_.generation;
  d.restart = !d.stale && job.generation != generation_;
  if (!d.stale)
  {
    generation_ = job.generation;
  }
  d.relocalizing = state_.relocalizing;
  if (!d.stale)
  {
    d.hint.swap(state_.pending_hint);  // a stale batch leaves the hint for the next one
  }
  return d;
}

void SolverWorker::startGlobalSearch(const Job& job)
{
  updates_since_global_ = 0;
  core::Localizer* localizer = global_localizer_.get();
  const std::vector<core::Reading> readings = job.readings;
  global_search_.emplace();
  global_search_->result =
      std::async(std::launch::async, [localizer, readings] { return localizer->localize(readings); });
  global_search_->reference = job.batch.base_first;
  global_search_->generation = generation_;
  global_search_->readings = job.readings.size();
}

std::string SolverWorker::collectGlobalSearch()
{
  if (!global_search_)
  {
    return std::string();
  }
  if (global_search_->result.wait_for(std::chrono::seconds(0)) != std::future_status::ready)
  {
    global_search_->since = std::min<std::size_t>(global_search_->since + 1, core::kMaxCatchUp);
    return std::string();
  }
  PendingSearch search = std::move(*global_search_);
  global_search_.reset();
  const core::Result global = search.result.get();
  if (search.generation != generation_)
  {
    return std::string();
  }
  handover_pending_ = true;
  // The candidates are poses of the base at the search's batch: as map -> odom transforms they
  // hold now too (the tracker keeps hypotheses as map -> odom). A search cut short proves nothing
  // about the places it did not finish: a lone candidate of it could look unique when it is not.
  if (!global.truncated)
  {
    tracker_->seed(global.candidates, search.reference, 0.0, search.since);
  }
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    ++state_.tracking.global_searches;
  }
  char text[200];
  std::snprintf(text, sizeof(text),
                "global search: %zu candidate(s)%s in %.3f s%s, carried through %zu later batches; %zu hypotheses",
                global.candidates.size(),
                global.candidates.empty() ? "" :
                                            (", the best explains " + std::to_string(global.candidates[0].inliers) +
                                             " of " + std::to_string(search.readings) + " readings")
                                                .c_str(),
                global.times.total, global.truncated ? " (cut short: not seeded)" : "", search.since,
                tracker_->hypotheses().size());
  return text;
}

std::string SolverWorker::applyHint(const PoseHint& hint, const Job& job)
{
  const core::TrackerOptions& o = tracker_->options();
  const auto half = [](double variance, double lo, double hi) {
    const double sigma3 = 3.0 * std::sqrt(std::max(0.0, variance));
    return std::isfinite(sigma3) ? std::min(hi, std::max(lo, sigma3)) : hi;
  };
  const double xy = half(std::max(hint.covariance(0, 0), hint.covariance(1, 1)), o.box_min_xy, 5.0);
  const double theta = half(hint.covariance(2, 2), o.box_min_theta, core::kPi);
  // The hint is the base now (about the newest reading): carried back to the batch's reference.
  const core::Pose2 p = core::compose(hint.pose, core::between(job.batch.base_newest, job.batch.base_first));
  const core::PoseBox box{ p.x - xy, p.x + xy, p.y - xy, p.y + xy, p.theta - theta, p.theta + theta };
  const core::HintOutcome outcome = tracker_->seedFromHint(box, job.readings, job.batch.base_first);
  char text[300];
  if (!outcome.accepted)
  {
    std::snprintf(text, sizeof(text),
                  "initialpose refused: no pose within its 3-sigma box (+-%.2f m, +-%.2f rad) explains %d of the %zu "
                  "readings; the best found explains %d",
                  xy, theta, outcome.min_consensus, job.readings.size(), std::max(0, outcome.best_consensus));
    return text;
  }
  updates_since_global_ = 0;
  handover_pending_ = false;  // the user set the pose: nothing to hand over
  std::snprintf(text, sizeof(text),
                "initialpose accepted: %d hypothes%s in its 3-sigma box, the best explains %d of %zu",
                outcome.hypotheses, outcome.hypotheses == 1 ? "is" : "es", outcome.best_consensus, job.readings.size());
  return text;
}

core::Result SolverWorker::trackedResult(const Job& job) const
{
  core::Result result;
  const int k = static_cast<int>(job.readings.size());
  result.readings_used = k;
  result.min_inliers_used = tracker_->minConsensus(k);
  result.engine = localizer_->options().engine;
  result.method = localizer_->options().method;
  for (const core::Hypothesis& h : tracker_->hypotheses())
  {
    core::Candidate c = h.last_fix;
    c.pose = core::compose(h.map_to_odom, job.batch.base_first);
    c.support = h.support;
    c.covariance = h.covariance;
    c.inlier_mask.resize(job.readings.size(), false);
    result.candidates.push_back(c);
  }
  return result;
}

std::string SolverWorker::stepTracker(const Directive& directive, const Job& job)
{
  try
  {
    if (directive.hint)
    {
      return applyHint(*directive.hint, job);
    }
    const std::string event = collectGlobalSearch();
    // New places while relocalizing (always in continuous mode); confirmations in any mode.
    const bool searching = directive.relocalizing || solveMode(params_) == SolveMode::Continuous;
    if (!global_search_ && tracker_->wantsGlobalSearch(searching, updates_since_global_, params_.global_interval))
    {
      startGlobalSearch(job);
    }
    // Every batch, with hypotheses or not: the tracker remembers it for the places a search brings.
    updates_since_global_ += tracker_->hypotheses().empty() ? 0 : 1;
    tracker_->update(job.readings, job.batch.base_first);
    return event;
  }
  catch (const std::exception& error)
  {
    return std::string("tracking failed: ") + error.what();
  }
}

std::string SolverWorker::lostTrackEvent(core::TrackState track, bool* kidnap)
{
  *kidnap = was_tracking_ && track == core::TrackState::Lost;
  was_tracking_ = tracker_->clearlySupported() != nullptr || (was_tracking_ && track != core::TrackState::Lost);
  if (!*kidnap)
  {
    return std::string();
  }
  const std::string missed =
      "every hypothesis missed " + std::to_string(params_.tracker.lost_updates) + " updates in a row";
  return solveMode(params_) == SolveMode::Continuous ? "kidnap detected: " + missed + "; relocalizing" :
                                                       "track lost: " + missed + "; call ~relocalize";
}

void SolverWorker::publishTracking(const Job& job, const core::Result& result, const Outcome& outcome)
{
  // Without hypotheses (on_request mode before a request, or lost) one empty result says so.
  const bool empty = result.candidates.empty();
  if (!empty || !published_empty_)
  {
    publisher_.publishBatch(job, result, outcome, outcome.success, *map_);
  }
  published_empty_ = empty;
  const core::Hypothesis* supported = tracker_->clearlySupported();
  if (!supported)
  {
    return;
  }
  if (params_.publish_tf)
  {
    publisher_.publishMapToOdom(supported->map_to_odom);
  }
  if (params_.publish_initialpose && handover_pending_)
  {
    handover_pending_ = false;
    publisher_.publishInitialPose(job, result.candidates.front(), *map_);
  }
}

Outcome SolverWorker::trackBatch(const Job& job)
{
  const auto start = std::chrono::steady_clock::now();
  const Directive directive = takeDirective(job);
  Outcome outcome;
  if (directive.stale)
  {
    outcome.message = "a batch formed before the latest relocalization request: skipped";
    return outcome;
  }
  if (directive.restart)
  {
    tracker_->clear();
    updates_since_global_ = 0;
    was_tracking_ = false;
  }
  std::string event = stepTracker(directive, job);
  const core::TrackState track = tracker_->state();
  bool kidnap = false;
  const std::string lost = lostTrackEvent(track, &kidnap);
  event = lost.empty() ? event : lost;
  traceHypotheses(*tracker_, job);
  core::Result result = trackedResult(job);
  result.times.total = core::secondsSince(start);
  outcome.success = tracker_->clearlySupported() != nullptr;
  outcome.message = describeTracking(*tracker_, static_cast<int>(job.readings.size()));
  outcome.result = resultMessage(job, result);
  outcome.result.unambiguous = outcome.success;
  const std::vector<OutcomePromise> waiters = recordTracking(job, event, kidnap, statusOf(track), &outcome);
  publishTracking(job, result, outcome);
  for (const OutcomePromise& waiter : waiters)
  {
    waiter->set_value(outcome);
  }
  if (!event.empty())
  {
    const bool warn = kidnap || event.rfind("initialpose refused", 0) == 0 || event.rfind("tracking failed", 0) == 0;
    ROS_LOG(warn ? ros::console::levels::Warn : ros::console::levels::Info, ROSCONSOLE_DEFAULT_NAME,
            "fdml_localizer: %s", event.c_str());
  }
  return outcome;
}

std::vector<OutcomePromise> SolverWorker::recordTracking(const Job& job, const std::string& event, bool kidnap,
                                                         std::uint8_t state, Outcome* outcome)
{
  std::vector<OutcomePromise> waiters;
  fdml_localization::Status status;
  {
    std::lock_guard<std::mutex> lock(state_.mutex);
    setDropCounts(state_.buffer.dropCounts(), &outcome->result);
    NodeStatistics& stats = state_.stats;
    ++stats.batches_solved;
    stats.last_solve_time = outcome->result.solve_time;
    stats.last_candidates = static_cast<int>(outcome->result.candidates.size());
    stats.last_unambiguous = outcome->success;
    TrackingStatus& tracking = state_.tracking;
    tracking.state = state;
    tracking.message = event.empty() ? outcome->message : event;
    tracking.hypotheses = static_cast<int>(tracker_->hypotheses().size());
    tracking.best_support = tracking.hypotheses > 0 ? tracker_->hypotheses()[0].support : 0.0;
    tracking.second_support = tracking.hypotheses > 1 ? tracker_->hypotheses()[1].support : 0.0;
    tracking.received_at_update = state_.buffer.received();
    tracking.kidnaps_detected += kidnap ? 1 : 0;
    if (kidnap && solveMode(params_) == SolveMode::Continuous)
    {
      state_.relocalizing = true;
    }
    // A batch formed before the latest relocalization request never brings map -> odom back.
    state_.have_map_to_odom = outcome->success && job.generation == state_.generation;
    if (state_.have_map_to_odom)
    {
      state_.map_to_odom = tracker_->clearlySupported()->map_to_odom;
      if (state_.relocalizing)
      {
        state_.relocalizing = false;
        waiters.swap(state_.relocalize_waiters);
      }
    }
    state_.activity = state_.relocalizing ? "relocalizing" : core::toString(tracker_->state());
    status = state_.statusLocked();
  }
  publisher_.publishStatus(status);
  return waiters;
}

}  // namespace fdml_localization
