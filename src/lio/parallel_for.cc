#include "swarmlio/lio/parallel_for.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <thread>

#if defined(__SANITIZE_THREAD__)
#define SWARMLIO_THREAD_SANITIZER 1
#elif defined(__has_feature)
#if __has_feature(thread_sanitizer)
#define SWARMLIO_THREAD_SANITIZER 1
#endif
#endif

namespace swarmlio::lio {

namespace {

// Threads for `threads` = 0: the machine's cores, at most this many.
constexpr int kMaxDefaultThreads = 4;

}  // namespace

struct ParallelFor::Arena {
  explicit Arena(int threads) : arena(threads) {}
  mutable tbb::task_arena arena;
};

ParallelFor::ParallelFor(int threads) {
  if (threads <= 0) {
    const int hardware = static_cast<int>(std::thread::hardware_concurrency());
    threads = std::max(1, std::min(hardware, kMaxDefaultThreads));
  }
#ifdef SWARMLIO_THREAD_SANITIZER
  // ThreadSanitizer cannot check TBB: Debian's libtbb is not instrumented,
  // so TSan misses its fork and join, and TBB's own header templates race
  // in its eyes (a suppression for them hides the loop bodies' races too).
  // Under TSan the loops run on the caller; their independence of the
  // thread count is checked in the Release build
  // (OdometryEndToEnd.SameEstimateForAnyThreadCount).
  threads = 1;
#endif
  if (threads > 1) arena_ = std::make_unique<Arena>(threads);
}

ParallelFor::~ParallelFor() = default;

void ParallelFor::Run(int64_t n, int64_t grain,
                      const std::function<void(int64_t, int64_t)>& body) const {
  if (n <= 0) return;
  grain = std::max<int64_t>(1, grain);
  if (arena_ == nullptr || n <= grain) {
    for (int64_t begin = 0; begin < n; begin += grain) body(begin, std::min(n, begin + grain));
    return;
  }
  arena_->arena.execute([&] {
    tbb::parallel_for(
        tbb::blocked_range<int64_t>(0, n, grain),
        [&](const tbb::blocked_range<int64_t>& r) { body(r.begin(), r.end()); },
        tbb::simple_partitioner());
  });
}

}  // namespace swarmlio::lio
