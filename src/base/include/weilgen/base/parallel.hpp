// Deterministic parallel loops: work is cut into fixed blocks whose boundaries do not depend
// on the thread count, so per-block random streams and per-block partial sums (reduced in
// block order) give bit-identical results for any --threads value.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <vector>

namespace weilgen {

// Number of worker threads for a request: 0 means all hardware threads.
inline unsigned resolve_threads(unsigned requested) {
  if (requested > 0) return requested;
  const unsigned hw = std::thread::hardware_concurrency();
  return hw > 0 ? hw : 1;
}

namespace parallel_detail {
// True on the threads of a parallel_blocks call: a loop nested in another runs on its caller's
// thread alone (the outer loop already keeps the cores busy; no threads beyond the request).
inline thread_local bool in_worker = false;
}  // namespace parallel_detail

// Cooperative cancellation of a long run (the Python module's Ctrl-C): a front end installs a
// flag for the running thread with CancelScope; parallel_blocks checks it before every block, in
// every worker, and long sequential loops call throw_if_cancelled(); once the flag is set they
// throw Cancelled, which unwinds the run.
struct Cancelled : std::runtime_error {
  Cancelled() : std::runtime_error("cancelled") {}
};

inline const std::atomic<bool>*& current_cancel_flag() {
  thread_local const std::atomic<bool>* flag = nullptr;
  return flag;
}

class CancelScope {
 public:
  explicit CancelScope(const std::atomic<bool>* flag) : previous_(current_cancel_flag()) {
    current_cancel_flag() = flag;
  }
  ~CancelScope() { current_cancel_flag() = previous_; }
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;

 private:
  const std::atomic<bool>* previous_;
};

inline void throw_if_cancelled() {
  const std::atomic<bool>* flag = current_cancel_flag();
  if (flag && flag->load(std::memory_order_relaxed)) throw Cancelled();
}

// Calls body(block, begin, end, thread) for blocks [k*block_size, min(n, (k+1)*block_size)).
// `thread` is in [0, threads) and identifies the caller's per-thread workspace. Exceptions
// from a body are rethrown on the calling thread (the first one wins); a cancelled run
// (CancelScope) throws Cancelled before its next block. Called from inside another
// parallel_blocks body, it runs serially (thread 0) on the calling thread.
template <typename Body>
void parallel_blocks(std::size_t n, std::size_t block_size, unsigned threads, Body&& body) {
  if (n == 0) return;
  block_size = std::max<std::size_t>(1, block_size);
  const std::size_t blocks = (n + block_size - 1) / block_size;
  threads = parallel_detail::in_worker
                ? 1u
                : std::max(1u, std::min<unsigned>(
                                   resolve_threads(threads),
                                   static_cast<unsigned>(std::min<std::size_t>(blocks, 1u << 16))));
  std::atomic<std::size_t> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const std::atomic<bool>* cancel = current_cancel_flag();
  auto worker = [&](unsigned t) {
    const CancelScope scope(cancel);  // nested loops and callbacks in this worker see it too
    for (;;) {
      const std::size_t k = next.fetch_add(1);
      if (k >= blocks) return;
      try {
        throw_if_cancelled();
        body(k, k * block_size, std::min(n, (k + 1) * block_size), t);
      } catch (...) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!error) error = std::current_exception();
        next = blocks;
        return;
      }
    }
  };
  if (threads == 1) {
    worker(0);
  } else {
    std::vector<std::thread> pool;
    for (unsigned t = 0; t < threads; ++t)
      pool.emplace_back([&worker, t] {
        parallel_detail::in_worker = true;
        worker(t);
      });
    for (auto& th : pool) th.join();
  }
  if (error) std::rethrow_exception(error);
}

}  // namespace weilgen
