// NodeletQueues: keeps a nodelet's two callback queues alive for as long as the nodelet.
//
// nodelet 1.10's manager owns a nodelet's single-threaded and multi-threaded queues beside the
// nodelet and frees them when it unloads the nodelet (on ~unload_nodelet, a broken bond, or
// the manager's shutdown). If a manager thread is running one of the nodelet's callbacks at
// that moment, that thread holds the last reference to the nodelet and destroys it after the
// callback: by then the *other* queue may be freed, and destroying a timer, subscriber or
// service created on it calls into freed memory (seen in CI as a SEGV in ros::Timer::~Timer
// under ASan: a cloud callback on the single-threaded queue while tf_timer_, on the
// multi-threaded one, was destroyed). A nodelet that holds both queues, as its first member so
// that they go last, makes that order safe.
#pragma once

#include <boost/shared_ptr.hpp>
#include <boost/smart_ptr/bad_weak_ptr.hpp>
#include <nodelet/detail/callback_queue.h>
#include <nodelet/nodelet.h>

namespace cube_scan_matcher {

class NodeletQueues {
 public:
  /// Takes shared ownership of the nodelet's queues. Call at the start of onInit(), before any
  /// handle is created. Queues the manager does not own through a shared_ptr (a standalone
  /// nodelet's global queue) are left alone: their owner outlives the nodelet anyway.
  void hold(ros::CallbackQueueInterface& st_queue, ros::CallbackQueueInterface& mt_queue) {
    st_ = share(st_queue);
    mt_ = share(mt_queue);
  }

 private:
  static boost::shared_ptr<const void> share(ros::CallbackQueueInterface& queue) {
    auto* managed = dynamic_cast<nodelet::detail::CallbackQueue*>(&queue);
    if (managed == nullptr) return {};
    try {
      return managed->shared_from_this();
    } catch (const boost::bad_weak_ptr&) {  // not owned by a shared_ptr: not a manager's
      return {};
    }
  }

  boost::shared_ptr<const void> st_, mt_;
};

}  // namespace cube_scan_matcher
