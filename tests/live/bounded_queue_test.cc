// BoundedQueue: FIFO order, capacity, TryPush/TryPop, timed pop, Close
// draining, and a producer/consumer pair that blocks on a full queue.
#include "swarmlio/live/bounded_queue.h"

#include <gtest/gtest.h>

#include <thread>
#include <vector>

namespace swarmlio::live {
namespace {

TEST(BoundedQueue, FifoWithinCapacity) {
  BoundedQueue<int> q(3);
  EXPECT_EQ(q.capacity(), 3u);
  EXPECT_TRUE(q.TryPush(1));
  EXPECT_TRUE(q.TryPush(2));
  EXPECT_TRUE(q.Push(3));
  EXPECT_FALSE(q.TryPush(4));  // full: not queued
  EXPECT_EQ(q.size(), 3u);
  EXPECT_EQ(q.TryPop(), 1);
  EXPECT_EQ(q.Pop(), 2);
  EXPECT_EQ(q.PopFor(1'000'000), 3);
  EXPECT_EQ(q.TryPop(), std::nullopt);
  EXPECT_EQ(q.PopFor(1'000'000), std::nullopt);  // timeout
}

TEST(BoundedQueue, ZeroCapacityIsOne) {
  BoundedQueue<int> q(0);
  EXPECT_EQ(q.capacity(), 1u);
  EXPECT_TRUE(q.TryPush(1));
  EXPECT_FALSE(q.TryPush(2));
}

TEST(BoundedQueue, CloseDrainsThenEnds) {
  BoundedQueue<int> q(4);
  ASSERT_TRUE(q.Push(7));
  ASSERT_TRUE(q.Push(8));
  q.Close();
  EXPECT_TRUE(q.closed());
  EXPECT_FALSE(q.Push(9));
  EXPECT_FALSE(q.TryPush(9));
  EXPECT_EQ(q.Pop(), 7);
  EXPECT_EQ(q.Pop(), 8);
  EXPECT_EQ(q.Pop(), std::nullopt);  // closed and empty: no wait
}

TEST(BoundedQueue, CloseWakesABlockedProducerAndConsumer) {
  BoundedQueue<int> full(1);
  ASSERT_TRUE(full.Push(1));
  BoundedQueue<int> empty(1);
  bool pushed = true;
  std::optional<int> popped = 5;
  std::thread producer([&] { pushed = full.Push(2); });
  std::thread consumer([&] { popped = empty.Pop(); });
  full.Close();
  empty.Close();
  producer.join();
  consumer.join();
  EXPECT_FALSE(pushed);
  EXPECT_EQ(popped, std::nullopt);
}

TEST(BoundedQueue, ProducerConsumerKeepsOrderAndBound) {
  constexpr int kItems = 20000;
  BoundedQueue<int> q(8);
  std::thread producer([&] {
    for (int i = 0; i < kItems; ++i) ASSERT_TRUE(q.Push(i));
    q.Close();
  });
  std::vector<int> received;
  size_t max_size = 0;
  while (std::optional<int> x = q.Pop()) {
    received.push_back(*x);
    max_size = std::max(max_size, q.size());
  }
  producer.join();
  ASSERT_EQ(received.size(), static_cast<size_t>(kItems));
  for (int i = 0; i < kItems; ++i) ASSERT_EQ(received[i], i);
  EXPECT_LE(max_size, 8u);
}

}  // namespace
}  // namespace swarmlio::live
