#pragma once
// The learner service's message handlers, apart from main() so that tests build them on an
// in-process bus (docs/architecture.md, "Testing a service's handlers in one process";
// the protocol: docs/learning.md).
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "learner/learn_worker.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/learn_commit_t.hpp"
#include "nudge/learn_result_t.hpp"
#include "nudge/learn_view_t.hpp"
#include "nudge/learning/database.hpp"
#include "nudge/learning/recognizer.hpp"
#include "nudge/recognize_request_t.hpp"

namespace nudge::learner_service {

struct Options {
  std::string db_dir;
  learning::LearnParams learn;
  learning::RecognizeParams recognize;
  double view_expiry_s = 300;   // views not committed within this much message time are dropped
  int max_views = 64;           // view_index must be below this
  int max_pending_objects = 8;  // objects gathering views at once; the oldest is dropped beyond
};

// Subscribes the started `service` to LEARN_VIEW, LEARN_COMMIT and RECOGNIZE_REQUEST; answers on
// LEARNED and RECOGNITION. Opens the database at construction (throws learning::DatabaseError when
// its folder cannot be made) and loads every object it can, reporting the others.
// Learning runs on a worker thread (LearnWorker): LEARN_COMMIT's handler returns at once, poll()
// (the service loop's tick) keeps the heartbeat's status at "learning <object_key> (view k/n)" and
// answers LEARNED when the worker is done. A LEARN_COMMIT while one is learned is refused (LEARNED
// not ok, "busy learning ..."), its views kept for the same commit sent again.
class Handlers {
 public:
  Handlers(bus::Service& service, const Options& options);
  Handlers(const Handlers&) = delete;
  Handlers& operator=(const Handlers&) = delete;

  int known_objects() const { return recognizer_.size(); }
  int pending_objects() const { return static_cast<int>(pending_.size()); }
  bool learning() const { return worker_.busy(); }

  // On the LCM thread, often (the service loop's tick): the heartbeat status, LEARNED for a job
  // the worker ended, the new object in the recognizer.
  void poll();
  // Waits for the worker's job, then poll(): tests, and the last answer before the service stops.
  void finish_learning();

 private:
  struct Pending {
    std::map<int, learning::TrainingImage> views;  // by view_index
    cv::Mat scene;                                 // learn_view_t::KIND_SCENE's still, or empty
    std::string bad_views;                         // why views were refused, for the commit's answer
    int64_t last_utime = 0;
  };
  using Key = std::pair<std::string, std::string>;  // (run_id, object_key)
  struct Job {  // written by the worker while it runs, read by poll() after it ended
    learn_result_t answer;
    learning::ObjectModel model;
    learning::LearnStats stats;
  };

  void on_view(const learn_view_t& msg);
  void on_commit(const learn_commit_t& msg);
  void on_recognize(const recognize_request_t& msg);
  void expire(int64_t now_utime);
  void report(const std::string& what);  // logged and counted in the heartbeat
  void learned(const LearnWorker::Ended& ended);

  bus::Service& service_;
  Options options_;
  learning::ObjectDatabase db_;
  learning::Recognizer recognizer_;
  std::map<Key, Pending> pending_;
  Job job_;
  LearnWorker worker_;  // last: its thread ends before the members its job uses go
};

}  // namespace nudge::learner_service
