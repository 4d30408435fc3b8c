#pragma once
// One worker thread for the learner's long job (SIFT on every view, pruning, the database write:
// seconds to tens of seconds), so that the LCM thread keeps handling messages and the heartbeat
// keeps saying what the learner does. A queue of one: a job submitted while another is running or
// unanswered is refused (docs/learning.md, "While it learns").
#include <condition_variable>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

namespace nudge::learner_service {

class LearnWorker {
 public:
  // Reports progress (views done, views in all) from the worker thread.
  using Progress = std::function<void(int done, int total)>;
  // The job's body: runs on the worker thread; an exception becomes the job's error.
  using Body = std::function<void(const Progress& progress)>;

  LearnWorker();
  ~LearnWorker();  // waits for a running job to end
  LearnWorker(const LearnWorker&) = delete;
  LearnWorker& operator=(const LearnWorker&) = delete;

  // Starts `body` named `what` (e.g. "attempt_03"). False, nothing started, when a job is running
  // or its end was not taken yet.
  bool submit(const std::string& what, Body body);
  // The name of the job that ended and its error ("" when it succeeded), once; nullopt while one
  // runs or none was submitted. Frees the worker for the next job.
  struct Ended {
    std::string what;
    std::string error;
  };
  std::optional<Ended> take_ended();
  bool busy() const;
  // "learning <what> (view k/n)" while a job runs, "" otherwise.
  std::string status() const;
  // Blocks until no job is running (its end may still be waiting to be taken).
  void wait_until_ended();

 private:
  void loop();

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  Body body_;                         // the job waiting to start
  std::string what_;                  // the current job's name
  int done_ = 0, total_ = 0;          // its progress
  bool running_ = false, stopping_ = false;
  std::optional<Ended> ended_;
  std::thread thread_;                // last: starts after the members it uses
};

}  // namespace nudge::learner_service
