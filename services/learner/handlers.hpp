#pragma once
// The learner service's message handlers, apart from main() so that tests build them on an
// in-process bus (docs/architecture.md, "Testing a service's handlers in one process";
// the protocol: docs/learning.md).
#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>

#include "nudge/bus/service.hpp"
#include "nudge/learn_commit_t.hpp"
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
class Handlers {
 public:
  Handlers(bus::Service& service, const Options& options);
  Handlers(const Handlers&) = delete;
  Handlers& operator=(const Handlers&) = delete;

  int known_objects() const { return recognizer_.size(); }
  int pending_objects() const { return static_cast<int>(pending_.size()); }

 private:
  struct Pending {
    std::map<int, learning::TrainingImage> views;  // by view_index
    std::string bad_views;                         // why views were refused, for the commit's answer
    int64_t last_utime = 0;
  };
  using Key = std::pair<std::string, std::string>;  // (run_id, object_key)

  void on_view(const learn_view_t& msg);
  void on_commit(const learn_commit_t& msg);
  void on_recognize(const recognize_request_t& msg);
  void expire(int64_t now_utime);
  void report(const std::string& what);  // logged and counted in the heartbeat

  bus::Service& service_;
  Options options_;
  learning::ObjectDatabase db_;
  learning::Recognizer recognizer_;
  std::map<Key, Pending> pending_;
};

}  // namespace nudge::learner_service
