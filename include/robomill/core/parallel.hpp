#pragma once
// Parallel loops over independent work items (spindle speeds, samples,
// postures). Each index is handled exactly once and writes only its own
// result slot, so results do not depend on the thread count.

#include <algorithm>
#include <cstddef>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace robomill::core {

/// Number of worker threads for a request: `requested` if positive, else the
/// hardware concurrency (at least 1).
inline int resolve_thread_count(int requested) noexcept {
  if (requested > 0)
    return requested;
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware == 0 ? 1 : static_cast<int>(hardware);
}

/// Calls block(begin, end) on up to `threads` threads, the blocks covering
/// [0, count) contiguously; each block can own a workspace (a solver, scratch
/// matrices) for all its items. Exceptions propagate as in parallel_for.
template <class Block>
void parallel_blocks(std::size_t count, int threads, Block&& block) {
  const std::size_t workers =
      std::min<std::size_t>(static_cast<std::size_t>(resolve_thread_count(threads)), count);
  if (workers <= 1) {
    if (count > 0)
      block(std::size_t{0}, count);
    return;
  }
  std::exception_ptr failure;
  std::mutex failure_mutex;
  std::vector<std::thread> pool;
  pool.reserve(workers);
  for (std::size_t w = 0; w < workers; ++w) {
    const std::size_t begin = count * w / workers;
    const std::size_t end = count * (w + 1) / workers;
    pool.emplace_back([&, begin, end] {
      try {
        block(begin, end);
      } catch (...) {
        const std::lock_guard lock(failure_mutex);
        if (!failure)
          failure = std::current_exception();
      }
    });
  }
  for (std::thread& worker : pool)
    worker.join();
  if (failure)
    std::rethrow_exception(failure);
}

/// Calls body(i) for i in [0, count) on up to `threads` threads in contiguous
/// blocks. The first exception thrown by any body is rethrown on the caller's
/// thread after all workers stop.
template <class Body>
void parallel_for(std::size_t count, int threads, Body&& body) {
  parallel_blocks(count, threads, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i)
      body(i);
  });
}

}  // namespace robomill::core
