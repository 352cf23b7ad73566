// The package's one thread runner: the coarse starts, the refine candidates and the grid builds
// run on it.
#pragma once

#include <algorithm>
#include <thread>
#include <vector>

namespace cube_scan_matcher {

/// Runs job(k, t) for k = 0..count-1 on min(threads, count) threads, the caller's thread being
/// thread 0: job k runs on thread t = k % threads, so a job can use thread t's own workspace.
/// Returns when every job is done. Jobs must not throw (catch inside and report).
template <typename Job>
void runOnThreads(int count, int threads, const Job& job) {
  threads = std::max(1, std::min(threads, count));
  auto worker = [&](int t) {
    for (int k = t; k < count; k += threads) job(k, t);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace cube_scan_matcher
