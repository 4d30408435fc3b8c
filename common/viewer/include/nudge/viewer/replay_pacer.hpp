#pragma once
// When the next event of a replayed log is due, under the operator's controls: play at a speed,
// pause, and step (while paused, release events up to and including the next "step event", e.g.
// the next camera frame). Pure logic on two clocks: the log's timestamps and the wall clock, both
// in microseconds, so that it is tested without sleeping. nudge-replay is its shell.
#include <cstdint>
#include <string>

namespace nudge::viewer {

class ReplayPacer {
 public:
  // Throws std::invalid_argument when speed is not > 0.
  explicit ReplayPacer(double speed = 1.0, bool paused = false);

  // How long to wait before the event stamped `event_log_utime` is due: 0 now, > 0 microseconds,
  // or -1 while paused with no step requested (wait for a command).
  int64_t wait_us(int64_t event_log_utime, int64_t now_wall) const;
  // The event was published. A step ends after its step event.
  void released(int64_t event_log_utime, bool is_step_event, int64_t now_wall);

  void play(int64_t now_wall);
  void pause();
  void step();
  // Throws std::invalid_argument when speed is not > 0.
  void set_speed(double speed, int64_t now_wall);

  bool paused() const { return paused_; }
  bool stepping() const { return step_pending_; }
  double speed() const { return speed_; }
  // The log time of the last event released (0 before the first).
  int64_t position() const { return position_; }

 private:
  void anchor(int64_t now_wall);

  double speed_;
  bool paused_;
  bool step_pending_ = false;
  bool anchored_ = false;
  int64_t anchor_log_ = 0, anchor_wall_ = 0;
  int64_t position_ = 0;
};

// "play", "pause", "step", "speed" -> what the operator asked; throws std::invalid_argument
// naming anything else.
enum class ReplayCommand { kPlay, kPause, kStep, kSpeed };
ReplayCommand replay_command_from_name(const std::string& name);
std::string replay_command_name(ReplayCommand command);

}  // namespace nudge::viewer
