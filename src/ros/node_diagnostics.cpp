#include "fdml_localization/ros/node_diagnostics.h"

#include <string>

namespace fdml_localization
{
namespace
{
void summarize(const NodeState& state, diagnostic_updater::DiagnosticStatusWrapper& status)
{
  using diagnostic_msgs::DiagnosticStatus;
  const NodeStatistics& stats = state.stats;
  if (!state.have_map)
  {
    status.summary(stats.maps_rejected > 0 ? DiagnosticStatus::ERROR : DiagnosticStatus::WARN,
                   stats.maps_rejected > 0 ? "no usable map: " + stats.last_map_error : std::string("no map yet"));
  }
  else if (stats.last_candidates < 0)
  {
    status.summary(DiagnosticStatus::OK, "no batch solved yet (" + state.activity + ")");
  }
  else if (state.relocalizing)
  {
    status.summary(DiagnosticStatus::WARN, "relocalizing: " + state.tracking.message);
  }
  else if (state.tracking.state == fdml_localization::Status::TRACKING)
  {
    status.summary(DiagnosticStatus::OK, "tracking: " + state.tracking.message);
  }
  else if (state.tracking.state == fdml_localization::Status::AMBIGUOUS)
  {
    status.summary(DiagnosticStatus::WARN, "ambiguous (no pose published): " + state.tracking.message);
  }
  else
  {
    status.summary(DiagnosticStatus::WARN, "lost (no pose published): " + state.tracking.message);
  }
}
}  // namespace

void diagnoseLocked(const NodeState& state, const Params& params, diagnostic_updater::DiagnosticStatusWrapper& status)
{
  summarize(state, status);
  const NodeStatistics& stats = state.stats;
  status.add("state", state.activity);
  status.add("readings received", state.buffer.received());
  status.add("readings dropped", state.buffer.dropped());
  for (const auto& drop : state.buffer.dropCounts())
  {
    status.add("dropped: " + drop.first, drop.second);
  }
  status.add("sensor frames tracked", state.buffer.trackedFrames());
  status.add("sensor frames evicted", state.buffer.framesEvicted());
  status.add("readings waiting for tf", state.buffer.pendingCount());
  status.add("readings ready", state.buffer.resolvedCount());
  status.add("batches tracked", stats.batches_solved);
  status.add("batches dropped unsolved (the worker fell behind)", stats.batches_dropped);
  status.add("solver errors", stats.solve_errors);
  status.add("last update time [s]", stats.last_solve_time);
  const fdml_localization::Status tracking = state.statusLocked();
  status.add("tracking state", tracking.state_name);
  status.add("hypotheses", tracking.hypotheses);
  status.add("best support", tracking.best_support);
  status.add("second support", tracking.second_support);
  status.add("readings since the last update", tracking.readings_since_update);
  status.add("kidnaps detected", tracking.kidnaps_detected);
  status.add("global searches", tracking.global_searches);
  status.add("map", state.have_map ? state.map_source : std::string("(none yet)"));
  if (params.use_map_topic)
  {
    status.add("maps received", stats.maps_received);
    status.add("maps in use", stats.maps_accepted);
    status.add("maps rejected", stats.maps_rejected);
    status.add("maps replaced before conversion", stats.maps_replaced);
    status.add("last map error", stats.last_map_error);
  }
}

}  // namespace fdml_localization
