#include "fdml_localization/ros/node_state.h"

#include <utility>

namespace fdml_localization
{
void NodeState::queueBatchLocked(std::unique_ptr<Job> job)
{
  job->waiters.swap(relocalize_waiters);
  if (queued_batch)
  {
    // A newer batch replaces the queued one and inherits its waiters.
    ++stats.batches_replaced;
    job->waiters.insert(job->waiters.end(), queued_batch->waiters.begin(), queued_batch->waiters.end());
  }
  queued_batch = std::move(job);
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
  if (queued_batch)
  {
    waiters.insert(waiters.end(), queued_batch->waiters.begin(), queued_batch->waiters.end());
    queued_batch.reset();
  }
  for (const OutcomePromise& waiter : waiters)
  {
    waiter->set_value(failed);
  }
}

}  // namespace fdml_localization
