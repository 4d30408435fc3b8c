#pragma once
// The time a service runs on, one abstraction for every service (docs/architecture.md, "Time and
// determinism"). Time on the bus is a utime (microseconds) from one of three sources:
//   wall  the host's clock: live runs;
//   sim   the simulator's time, the utime of its SIM_STATE messages (the world may run faster or
//         slower than real time, and whatever moves with it must follow its time);
//   log   message time: the utime stamps of the messages a service reads from a log, so that the
//         service is a pure function from log to log however fast the log is read.
// BusClock says which stamps move a service's clock; LogTimeline maps message time onto the
// simulator's seconds when the world replays a log; Pacer runs simulated time against the wall.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include "nudge/timing.hpp"

namespace nudge {

enum class ClockSource { Wall, Sim, Log };

// "auto" (log when the input is a log file, else wall), "wall", "sim" or "log". Throws
// std::invalid_argument naming the choices otherwise.
ClockSource parse_clock_source(const std::string& name, bool input_is_log);
std::string clock_source_name(ClockSource source);

// Whose time a message's utime is.
enum class Stamp {
  Sender,     // the sender's clock: wall time live, the recorded time in a log
  Simulated,  // the simulator's (SIM_STATE)
};

using WallClock = std::function<int64_t()>;

class BusClock {
 public:
  explicit BusClock(ClockSource source, WallClock wall = wall_utime);

  ClockSource source() const { return source_; }

  // A message arrived: the time it moves the clock to, or nullopt when this clock does not follow
  // such stamps. Wall: the wall clock now (whatever the stamp); Sim: simulated stamps; Log: sender
  // stamps (simulated time does not mix with the senders' clocks). Never goes back: an earlier
  // stamp leaves the clock where it is and gives its current time.
  std::optional<int64_t> on_message(int64_t utime, Stamp stamp);

  // No message (a timer fired): the wall clock now for Wall; nullopt otherwise, since message
  // time moves only with messages.
  std::optional<int64_t> on_timer();

  // The latest time (nullopt before the clock first moved).
  std::optional<int64_t> now() const { return now_; }

  // Deadlines of senders that beat in real time (a supervisor's heartbeat) are judged on message
  // time when replaying a log, else on the wall clock, whichever the clock's source.
  bool deadlines_on_message_time() const { return source_ == ClockSource::Log; }
  int64_t deadline_time() const;

  int64_t wall() const { return wall_(); }

 private:
  int64_t move_to(int64_t utime);

  ClockSource source_;
  WallClock wall_;
  std::optional<int64_t> now_;
};

// Message time as seconds since an origin: the world service replaying a log applies each message
// at simulated time = (utime - origin). Without a given origin the first stamp sets it: 0 when
// it looks like simulated time (before 2001: counted from the simulator's start), else that stamp
// (wall-clock stamps: the log replays as if the world had run in real time while it was recorded).
class LogTimeline {
 public:
  static constexpr int64_t kWallClockUtime = 1000000000LL * 1000000LL;  // 2001-09-09
  static constexpr double kMaxSeconds = 86400.0;                       // the longest span: a day

  explicit LogTimeline(std::optional<int64_t> origin = std::nullopt) : origin_(origin) {}

  // Seconds since the origin. Throws std::invalid_argument for a stamp more than kMaxSeconds
  // after the origin (a stamp on another clock would otherwise run the physics for years).
  double seconds(int64_t utime);
  std::optional<int64_t> origin() const { return origin_; }

 private:
  std::optional<int64_t> origin_;
};

// Paces simulated time against the wall clock: simulated time runs `factor` times as fast as wall
// time. When the machine cannot keep up it falls behind, never skips, and re-anchors so that it
// does not rush to catch up afterwards (it simply runs slower than asked).
class Pacer {
 public:
  static constexpr double kMaxLag = 0.1;  // s of simulated time behind before re-anchoring

  // Throws std::invalid_argument unless factor > 0 and finite.
  explicit Pacer(double factor, WallClock wall = wall_utime);

  // The simulated time physics should have reached now, `sim_time` being where it is.
  double target(double sim_time);
  // Milliseconds of wall time until simulated time `due` is reached (at most 20).
  int wait_ms(double due, double sim_target) const;
  // How often it fell behind and re-anchored.
  int64_t slips() const { return slips_; }

 private:
  double factor_;
  WallClock wall_;
  bool anchored_ = false;
  int64_t anchor_wall_ = 0;
  double anchor_sim_ = 0;
  int64_t slips_ = 0;
};

}  // namespace nudge
