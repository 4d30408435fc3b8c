#pragma once
// Every service's health as the operator sees it, from the heartbeats it sends once a second:
// message rates, errors, last seen, and whether it is alive (a service silent for longer than
// `dead_after_s` is dead: with 1 Hz heartbeats and the default 2.5 s the page turns it red
// within 3 s).
#include <cstdint>
#include <map>
#include <string>
#include <vector>

namespace nudge::viewer {

// One heartbeat, as received. seen_utime is on the wall clock, or on the log's clock for a
// heartbeat played from a log (log_time): rows() judges each against the matching "now".
struct Heartbeat {
  std::string service, instance;
  int pid = 0;
  std::string state;  // "running", "degraded", ...
  int64_t messages_in = 0, messages_out = 0, errors = 0;
  std::string status;
  int64_t seen_utime = 0;
  bool log_time = false;
};

// "Now" on both clocks: the wall clock, and the replayed log's position (0 when none).
struct HealthClock {
  int64_t wall_utime = 0, log_utime = 0;
};

struct HealthRow {
  std::string name;  // service, or service/instance
  int pid = 0;
  std::string state;
  double in_per_s = 0, out_per_s = 0;  // between its last two heartbeats
  double heartbeat_hz = 0;             // 0 until two heartbeats came
  int64_t errors = 0;
  double last_seen_s = 0;  // seconds before `now`
  bool alive = false;
  std::string status;
};

class HealthTable {
 public:
  explicit HealthTable(double dead_after_s = 2.5) : dead_after_s_(dead_after_s) {}
  void observe(const Heartbeat& heartbeat);
  // One row per service ever seen, in name order.
  std::vector<HealthRow> rows(const HealthClock& now) const;

 private:
  struct Entry {
    Heartbeat last, previous;
    bool has_previous = false;
  };
  double dead_after_s_;
  std::map<std::string, Entry> services_;
};

}  // namespace nudge::viewer
