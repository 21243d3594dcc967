// ParallelFor: data-parallel loops over [0, n) on a fixed set of threads
// (docs/lio.md "Threads"). The loop body of an index writes only that
// index's own outputs, so results do not depend on the thread count; any
// reduction is left to the caller, in index order.
//
// Built on TBB (a task arena of `threads` slots, created once per owner, not
// per call; TBB's workers are shared by every arena of the process). With
// one thread the body runs inline on the caller, in index order; so it does
// in ThreadSanitizer builds, which cannot check TBB (parallel_for.cc).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>

namespace swarmlio::lio {

class ParallelFor {
 public:
  /// `threads` >= 1, or 0 for the machine's cores, at most 4.
  explicit ParallelFor(int threads);
  ~ParallelFor();
  ParallelFor(const ParallelFor&) = delete;
  ParallelFor& operator=(const ParallelFor&) = delete;

  /// Calls body(begin, end) for consecutive chunks of at most `grain`
  /// indices covering [0, n), possibly concurrently; returns when all ran.
  void Run(int64_t n, int64_t grain, const std::function<void(int64_t, int64_t)>& body) const;

 private:
  struct Arena;
  std::unique_ptr<Arena> arena_;  // null with one thread: the body runs on the caller
};

}  // namespace swarmlio::lio
