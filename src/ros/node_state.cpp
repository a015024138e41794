#include "fdml_localization/ros/node_state.h"

#include <ros/time.h>

#include <algorithm>
#include <utility>

namespace fdml_localization
{
void NodeState::queueBatchLocked(Job job)
{
  // Relocalization waiters stay in relocalize_waiters until a hypothesis is clearly supported;
  // a dropped batch's waiters (none today) move to the next one.
  queued_batches.push_back(std::move(job));
  while (queued_batches.size() > kMaxQueuedBatches)
  {
    std::vector<OutcomePromise>& next = queued_batches[1].waiters;
    next.insert(next.end(), queued_batches.front().waiters.begin(), queued_batches.front().waiters.end());
    queued_batches.pop_front();
    ++stats.batches_dropped;
  }
}

fdml_localization::Status NodeState::statusLocked() const
{
  fdml_localization::Status msg;
  msg.header.stamp = ros::Time::now();
  msg.state = relocalizing ? static_cast<std::uint8_t>(fdml_localization::Status::RELOCALIZING) : tracking.state;
  static const char* const kNames[] = { "tracking", "ambiguous", "lost", "relocalizing" };
  msg.state_name = msg.state < 4 ? kNames[msg.state] : "unknown";
  msg.message = tracking.message;
  msg.hypotheses = static_cast<std::uint32_t>(tracking.hypotheses);
  msg.best_support = tracking.best_support;
  msg.second_support = tracking.second_support;
  const std::uint64_t since = buffer.received() - std::min(buffer.received(), tracking.received_at_update);
  msg.readings_since_update = static_cast<std::uint32_t>(std::min<std::uint64_t>(since, 0xffffffffu));
  msg.kidnaps_detected = static_cast<std::uint32_t>(std::min<std::uint64_t>(tracking.kidnaps_detected, 0xffffffffu));
  msg.global_searches = static_cast<std::uint32_t>(std::min<std::uint64_t>(tracking.global_searches, 0xffffffffu));
  return msg;
}

void NodeState::failAllWaitersLocked(const std::string& message)
{
  Outcome failed;
  failed.message = message;
  std::vector<OutcomePromise> waiters;
  waiters.swap(relocalize_waiters);
  for (Job& job : queued_requests)
  {
    waiters.insert(waiters.end(), job.waiters.begin(), job.waiters.end());
  }
  queued_requests.clear();
  for (Job& job : queued_batches)
  {
    waiters.insert(waiters.end(), job.waiters.begin(), job.waiters.end());
  }
  queued_batches.clear();
  for (const OutcomePromise& waiter : waiters)
  {
    waiter->set_value(failed);
  }
}

}  // namespace fdml_localization
