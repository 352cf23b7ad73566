// runOnThreads: every job once, on one of min(threads, count) threads, the caller's being thread 0.
#include <gtest/gtest.h>

#include <algorithm>
#include <thread>
#include <vector>

#include "cube_scan_matcher/core/parallel.h"

using namespace cube_scan_matcher;

TEST(Parallel, RunsEveryJobOnceAndEachThreadIndexIsOneThread) {
  for (const int threads : {1, 2, 3, 8}) {
    const int count = 10;
    std::vector<int> runs(count, 0);  // element k is written by job k only
    std::vector<int> thread_of(count, -1);
    std::vector<std::thread::id> id_of(count);
    runOnThreads(count, threads, [&](int k, int t) {
      ++runs[std::size_t(k)];
      thread_of[std::size_t(k)] = t;
      id_of[std::size_t(k)] = std::this_thread::get_id();
    });
    const int used = std::min(threads, count);
    for (int k = 0; k < count; ++k) {
      EXPECT_EQ(runs[std::size_t(k)], 1) << k;
      EXPECT_GE(thread_of[std::size_t(k)], 0) << k;
      EXPECT_LT(thread_of[std::size_t(k)], used) << k;
      // Jobs of one thread index ran on one OS thread; thread 0 is the caller's.
      for (int j = 0; j < count; ++j) {
        if (thread_of[std::size_t(j)] == thread_of[std::size_t(k)]) {
          EXPECT_EQ(id_of[std::size_t(j)], id_of[std::size_t(k)]) << j << " " << k;
        }
        if (thread_of[std::size_t(k)] == 0) {
          EXPECT_EQ(id_of[std::size_t(k)], std::this_thread::get_id());
        }
      }
    }
  }
}

TEST(Parallel, NoJobNoCall) {
  int calls = 0;
  runOnThreads(0, 4, [&](int, int) { ++calls; });
  EXPECT_EQ(calls, 0);
}
