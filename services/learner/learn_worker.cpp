#include "learner/learn_worker.hpp"

#include <exception>

namespace nudge::learner_service {

LearnWorker::LearnWorker() : thread_([this] { loop(); }) {}

LearnWorker::~LearnWorker() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

bool LearnWorker::submit(const std::string& what, Body body) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (running_ || ended_ || body_) return false;
    what_ = what;
    done_ = total_ = 0;
    body_ = std::move(body);
    running_ = true;  // from now on: a second submit is refused even before the thread wakes
  }
  changed_.notify_all();
  return true;
}

std::optional<LearnWorker::Ended> LearnWorker::take_ended() {
  std::lock_guard<std::mutex> lock(mutex_);
  std::optional<Ended> ended = std::move(ended_);
  ended_.reset();
  return ended;
}

bool LearnWorker::busy() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return running_ || ended_.has_value();
}

std::string LearnWorker::status() const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!running_) return "";
  std::string text = "learning " + what_;
  if (total_ > 0) text += " (view " + std::to_string(done_) + "/" + std::to_string(total_) + ")";
  return text;
}

void LearnWorker::wait_until_ended() {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait(lock, [this] { return !running_; });
}

void LearnWorker::loop() {
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    changed_.wait(lock, [this] { return stopping_ || body_; });
    if (!body_) return;  // stopping with nothing to do
    Body body = std::move(body_);
    body_ = nullptr;
    const std::string what = what_;
    lock.unlock();
    std::string error;
    try {
      body([this](int done, int total) {
        std::lock_guard<std::mutex> progress_lock(mutex_);
        done_ = done;
        total_ = total;
      });
    } catch (const std::exception& e) {
      error = e.what();
      if (error.empty()) error = "learning failed";
    }
    lock.lock();
    ended_ = Ended{what, error};
    running_ = false;
    changed_.notify_all();
  }
}

}  // namespace nudge::learner_service
