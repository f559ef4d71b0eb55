// base/parallel.hpp: every block once, exceptions passed on, and a loop nested in another's body
// runs on its caller's thread alone.
#include <doctest/doctest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "weilgen/base/parallel.hpp"

using namespace weilgen;

TEST_CASE("parallel_blocks: every block once, for any thread count") {
  for (unsigned threads : {1u, 2u, 3u, 8u}) {
    std::vector<int> seen(1000, 0);
    parallel_blocks(seen.size(), 7, threads,
                    [&](std::size_t, std::size_t b, std::size_t e, unsigned t) {
                      CHECK(t < threads);
                      for (std::size_t i = b; i < e; ++i) ++seen[i];
                    });
    for (int s : seen) CHECK(s == 1);
  }
  CHECK_THROWS_AS(parallel_blocks(10, 1, 2,
                                  [](std::size_t k, std::size_t, std::size_t, unsigned) {
                                    if (k == 5) throw std::runtime_error("block 5");
                                  }),
                  std::runtime_error);
}

TEST_CASE("parallel_blocks: a nested loop runs serially on the outer body's thread") {
  std::atomic<int> nested_blocks{0}, foreign{0}, nonzero_thread{0};
  parallel_blocks(4, 1, 2, [&](std::size_t, std::size_t, std::size_t, unsigned) {
    const std::thread::id outer = std::this_thread::get_id();
    parallel_blocks(16, 1, 4, [&](std::size_t, std::size_t, std::size_t, unsigned t) {
      ++nested_blocks;
      if (std::this_thread::get_id() != outer) ++foreign;
      if (t != 0) ++nonzero_thread;
    });
  });
  CHECK(nested_blocks == 64);
  CHECK(foreign == 0);
  CHECK(nonzero_thread == 0);
  // Outside any loop the same call uses its threads again.
  std::atomic<int> others{0};
  const std::thread::id me = std::this_thread::get_id();
  parallel_blocks(16, 1, 4, [&](std::size_t, std::size_t, std::size_t, unsigned) {
    if (std::this_thread::get_id() != me) ++others;
  });
  CHECK(others == 16);
}
