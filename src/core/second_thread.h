// Private to the core: a second thread that runs one short job at a time for its owner, for
// work split into pieces too small to start a thread for each (the paired compass poll: two
// evaluations of some hundred microseconds each, tens of times per registration). Both sides
// spin briefly for the other (a hand-over of a microsecond on an idle core), then sleep on a
// condition variable (a loaded machine: no core burnt on waiting).
#pragma once

#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>

namespace cube_scan_matcher {

class SecondThread {
 public:
  SecondThread() : thread_([this] { loop(); }) {}
  /// Waits for a posted job to finish first.
  ~SecondThread() {
    wait();
    set(kQuit);
    thread_.join();
  }
  SecondThread(const SecondThread&) = delete;
  SecondThread& operator=(const SecondThread&) = delete;

  /// Starts `job` on the second thread; the previous job must be done (wait()). The job must
  /// not throw.
  void post(std::function<void()> job) {
    job_ = std::move(job);
    set(kPosted);
  }
  /// Returns when the posted job is done: its writes are visible to the caller.
  void wait() { await([](int s) { return s == kIdle; }); }

 private:
  enum State : int { kIdle, kPosted, kQuit };
  static constexpr int kSpins = 4000;  // polls of the state before sleeping (a few microseconds)

  void set(int s) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      state_.store(s, std::memory_order_release);
    }
    changed_.notify_all();
  }
  template <typename Ready>
  int await(Ready ready) {
    for (int i = 0; i < kSpins; ++i) {
      const int s = state_.load(std::memory_order_acquire);
      if (ready(s)) return s;
    }
    std::unique_lock<std::mutex> lock(mutex_);
    changed_.wait(lock, [&] { return ready(state_.load(std::memory_order_acquire)); });
    return state_.load(std::memory_order_acquire);
  }
  void loop() {
    for (;;) {
      if (await([](int s) { return s != kIdle; }) == kQuit) return;
      job_();
      set(kIdle);
    }
  }

  std::function<void()> job_;
  std::atomic<int> state_{kIdle};
  std::mutex mutex_;
  std::condition_variable changed_;
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace cube_scan_matcher
