// The worker's batch queue (no roscore needed): every sensor batch formed is kept for the worker
// in order, up to NodeState::kMaxQueuedBatches; beyond it the oldest is dropped and counted, and
// its waiters move to the next batch.
#include "fdml_localization/ros/node_state.h"

#include <gtest/gtest.h>

#include <future>
#include <memory>

namespace fdml_localization
{
namespace
{
Job batchNumbered(std::int64_t n)
{
  Job job;
  job.from_sensors = true;
  job.batch.newest_stamp = n;
  return job;
}

TEST(NodeStateQueue, KeepsEveryBatchInOrderWhileTheWorkerKeepsUp)
{
  // Four sensors firing together form two batches at stride 2 in one tf tick: both are kept
  // (a replacing slot lost half the tracking updates).
  NodeState state{ ReadingBuffer::Options() };
  state.queueBatchLocked(batchNumbered(1));
  state.queueBatchLocked(batchNumbered(2));
  state.queueBatchLocked(batchNumbered(3));
  ASSERT_EQ(state.queued_batches.size(), 3u);
  EXPECT_EQ(state.queued_batches[0].batch.newest_stamp, 1);
  EXPECT_EQ(state.queued_batches[1].batch.newest_stamp, 2);
  EXPECT_EQ(state.queued_batches[2].batch.newest_stamp, 3);
  EXPECT_EQ(state.stats.batches_dropped, 0u);
}

TEST(NodeStateQueue, DropsTheOldestBeyondTheBoundAndKeepsItsWaiters)
{
  NodeState state{ ReadingBuffer::Options() };
  const std::size_t extra = 3;
  Job first = batchNumbered(1);
  first.waiters.push_back(std::make_shared<std::promise<Outcome>>());
  state.queueBatchLocked(std::move(first));
  for (std::int64_t n = 2; n <= static_cast<std::int64_t>(NodeState::kMaxQueuedBatches + extra); ++n)
  {
    state.queueBatchLocked(batchNumbered(n));
  }
  ASSERT_EQ(state.queued_batches.size(), NodeState::kMaxQueuedBatches);
  EXPECT_EQ(state.stats.batches_dropped, extra);
  EXPECT_EQ(state.queued_batches.front().batch.newest_stamp, static_cast<std::int64_t>(extra + 1));
  EXPECT_EQ(state.queued_batches.back().batch.newest_stamp,
            static_cast<std::int64_t>(NodeState::kMaxQueuedBatches + extra));
  EXPECT_EQ(state.queued_batches.front().waiters.size(), 1u) << "a dropped batch's waiter is answered later";
  state.failAllWaitersLocked("shutting down");
  EXPECT_TRUE(state.queued_batches.empty());
}

}  // namespace
}  // namespace fdml_localization
