#pragma once
#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <future>
#include <mutex>
#include <thread>

namespace nudge {

// One thread that runs the tasks given to it, in order, for as long as it lives. Unlike a
// std::async thread made for each task, work kept on one thread finds what the last task left
// warm: the memory its allocator handed out (glibc gives each thread an arena; a new thread's
// pages fault in on first touch) and its caches. The supervisor's left-camera segmentation runs
// on one (docs/benchmarks.md, "Page faults").
class Worker {
 public:
  Worker();
  ~Worker();  // runs the tasks already given, then joins
  Worker(const Worker&) = delete;
  Worker& operator=(const Worker&) = delete;

  // Queues `task`; the future is ready when it has run (and carries its exception, if it threw).
  std::future<void> run(std::function<void()> task);
  std::thread::id id() const { return thread_.get_id(); }

 private:
  void loop();

  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::packaged_task<void()>> tasks_;
  bool stopping_ = false;
  std::thread thread_;  // last: started once the queue exists
};

// Waits for a running task's future when it goes out of scope unless its result was taken: the
// task may use the scope's locals (a Worker's future, unlike std::async's, does not wait when
// destroyed). A deferred task that never ran is left unrun.
struct WaitOnExit {
  std::future<void>& future;
  ~WaitOnExit() {
    if (future.valid() && future.wait_for(std::chrono::seconds(0)) != std::future_status::deferred) future.wait();
  }
};

}  // namespace nudge
