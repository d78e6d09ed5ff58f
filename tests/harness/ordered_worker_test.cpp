// OrderedWorker: items consumed in submission order on another thread, the queue bounded, the
// consumer's exception handed back to the producer.
#include "harness/base/ordered_worker.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace tgnav::harness {
namespace {

TEST(OrderedWorker, ConsumesEveryItemInOrderOnAnotherThread) {
  std::vector<int> seen;
  std::thread::id consumer;
  OrderedWorker<int> worker(2, [&](int& i) {
    seen.push_back(i);
    consumer = std::this_thread::get_id();
  });
  for (int i = 0; i < 1000; ++i) worker.submit(i);
  worker.finish();
  ASSERT_EQ(seen.size(), 1000u);
  for (int i = 0; i < 1000; ++i) EXPECT_EQ(seen[static_cast<std::size_t>(i)], i);
  EXPECT_NE(consumer, std::this_thread::get_id());
}

// The producer runs at most `capacity` items ahead of the one being consumed.
TEST(OrderedWorker, TheProducerWaitsWhileTheQueueIsFull) {
  std::atomic<int> consumed{0};
  std::atomic<int> max_ahead{0};
  std::atomic<int> submitted{0};
  OrderedWorker<int> worker(3, [&](int&) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
    const int ahead = submitted.load() - consumed.load();
    if (ahead > max_ahead.load()) max_ahead.store(ahead);
    ++consumed;
  });
  for (int i = 0; i < 50; ++i) {
    worker.submit(i);
    ++submitted;
  }
  worker.finish();
  EXPECT_EQ(consumed.load(), 50);
  EXPECT_LE(max_ahead.load(), 3 + 1);  // the queue plus the item in hand
}

TEST(OrderedWorker, TheConsumersExceptionReachesTheProducer) {
  OrderedWorker<int> worker(1, [](int& i) {
    if (i == 3) throw std::runtime_error("bad item 3");
  });
  bool thrown = false;
  try {
    for (int i = 0; i < 100; ++i) worker.submit(i);
    worker.finish();
  } catch (const std::runtime_error& e) {
    thrown = true;
    EXPECT_STREQ(e.what(), "bad item 3");
  }
  EXPECT_TRUE(thrown);
}

}  // namespace
}  // namespace tgnav::harness
