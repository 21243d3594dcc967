// BoundedQueue: a FIFO of at most `capacity` items shared by threads (the
// live process's input -> estimator and network -> estimator hand-offs,
// docs/online.md). Mutex + condition variables, header-only.
//
// Why not tbb::concurrent_bounded_queue (TBB is already a dependency): it
// has no timed pop, and its abort() makes the waiting calls throw instead of
// letting the consumer drain what is left after the producer finished.
//
//   live::BoundedQueue<int> q(64);
//   q.Push(1);                                   // blocks while full
//   std::optional<int> x = q.PopFor(2'000'000);  // waits up to 2 ms
//   q.Close();                                   // producers done: Pop drains, then nullopt
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <mutex>
#include <optional>
#include <utility>

namespace swarmlio::live {

template <class T>
class BoundedQueue {
 public:
  /// `capacity` >= 1 (0 is taken as 1).
  explicit BoundedQueue(size_t capacity) : capacity_(capacity == 0 ? 1 : capacity) {}
  BoundedQueue(const BoundedQueue&) = delete;
  BoundedQueue& operator=(const BoundedQueue&) = delete;

  /// Waits while full; false (item not queued) once the queue is closed.
  bool Push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_) return false;
    items_.push_back(std::move(item));
    lock.unlock();
    not_empty_.notify_one();
    return true;
  }

  /// Never waits: false when full or closed (the item is not queued).
  bool TryPush(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    if (closed_ || items_.size() >= capacity_) return false;
    items_.push_back(std::move(item));
    lock.unlock();
    not_empty_.notify_one();
    return true;
  }

  /// Waits for an item; nullopt once the queue is closed and empty.
  std::optional<T> Pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    return TakeFront(&lock);
  }

  /// Waits at most `timeout_ns`; nullopt on timeout or when closed and empty.
  std::optional<T> PopFor(int64_t timeout_ns) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait_for(lock, std::chrono::nanoseconds(timeout_ns),
                        [&] { return closed_ || !items_.empty(); });
    return TakeFront(&lock);
  }

  /// Never waits.
  std::optional<T> TryPop() {
    std::unique_lock<std::mutex> lock(mutex_);
    return TakeFront(&lock);
  }

  /// No more pushes (they return false); pops drain the remaining items.
  /// Wakes every waiting thread.
  void Close() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      closed_ = true;
    }
    not_empty_.notify_all();
    not_full_.notify_all();
  }

  bool closed() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_;
  }
  size_t size() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return items_.size();
  }
  size_t capacity() const { return capacity_; }

 private:
  std::optional<T> TakeFront(std::unique_lock<std::mutex>* lock) {
    if (items_.empty()) return std::nullopt;
    std::optional<T> item(std::move(items_.front()));
    items_.pop_front();
    lock->unlock();
    not_full_.notify_one();
    return item;
  }

  const size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable not_empty_;
  std::condition_variable not_full_;
  std::deque<T> items_;
  bool closed_ = false;
};

}  // namespace swarmlio::live
