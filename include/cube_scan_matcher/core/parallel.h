// The package's one thread runner: the coarse starts, the refine candidates and the grid builds
// run on it.
#pragma once

#include <algorithm>
#include <atomic>
#include <thread>
#include <vector>

namespace cube_scan_matcher {

/// Runs job(k, t) for k = 0..count-1 on min(threads, count) threads, the caller's thread being
/// thread 0: each thread takes the next job not yet taken, in the order of k (so put long jobs
/// first), and passes its own index t, so a job can use thread t's own workspace. A job's
/// result must not depend on t. Returns when every job is done. Jobs must not throw (catch
/// inside and report).
template <typename Job>
void runOnThreads(int count, int threads, const Job& job) {
  threads = std::max(1, std::min(threads, count));
  std::atomic<int> next{0};
  auto worker = [&](int t) {
    for (int k = next++; k < count; k = next++) job(k, t);
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < threads; ++t) pool.emplace_back(worker, t);
  worker(0);
  for (std::thread& t : pool) t.join();
}

}  // namespace cube_scan_matcher
