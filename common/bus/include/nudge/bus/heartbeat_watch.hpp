#pragma once
// Noticing that another service went quiet: LCM says nothing when a publisher dies, so a process
// that needs another's output watches its HEARTBEAT (once a second) and calls it silent after
// kSilentAfter without one. A heartbeat with STATE_STOPPING says goodbye: that one is not missed.
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "nudge/heartbeat_t.hpp"

namespace nudge::bus {

// 2.5 heartbeat periods: two missed beats, and a kill is noticed within 3 s whatever its phase.
constexpr int64_t kSilentAfterUs = 2500000;

class HeartbeatWatch {
 public:
  // Watches the services named (heartbeat_t::service); all services when `services` is empty.
  // Heartbeats of `own_pid` (this process) are ignored.
  explicit HeartbeatWatch(std::vector<std::string> services = {}, int32_t own_pid = -1,
                          int64_t silent_after_us = kSilentAfterUs);

  // receive_utime: when it arrived, on the clock later passed to silent() (the wall clock live).
  void on_heartbeat(const heartbeat_t& heartbeat, int64_t receive_utime);

  struct Silent {
    std::string source;  // "service" or "service/instance" when the instance differs
    double seconds = 0;  // since its last heartbeat
  };
  // Sources heard at least once, not stopped, and without a heartbeat for longer than the limit.
  std::vector<Silent> silent(int64_t now_utime) const;

 private:
  bool watched(const std::string& service) const;

  std::vector<std::string> services_;
  int32_t own_pid_;
  int64_t silent_after_us_;
  std::map<std::string, int64_t> last_seen_;  // source -> receive time of its last heartbeat
};

// "camera silent for 3.1 s, symmetry silent for 2.6 s"; "" when none is.
std::string describe(const std::vector<HeartbeatWatch::Silent>& silent);

}  // namespace nudge::bus
