#include "nudge/viewer/replay_pacer.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nudge::viewer {

namespace {
double checked_speed(double speed) {
  if (!(speed > 0) || !std::isfinite(speed))
    throw std::invalid_argument("replay speed must be > 0, got " + std::to_string(speed));
  return speed;
}
}  // namespace

ReplayPacer::ReplayPacer(double speed, bool paused) : speed_(checked_speed(speed)), paused_(paused) {}

int64_t ReplayPacer::wait_us(int64_t event_log_utime, int64_t now_wall) const {
  if (paused_) return step_pending_ ? 0 : -1;
  // The first event, or the first after a pause, plays at once; later ones keep the log's spacing.
  if (!anchored_) return 0;
  const double due = anchor_wall_ + (event_log_utime - anchor_log_) / speed_;
  return std::max<int64_t>(0, static_cast<int64_t>(std::ceil(due - now_wall)));
}

void ReplayPacer::released(int64_t event_log_utime, bool is_step_event, int64_t now_wall) {
  // The log's time went back (two logs back to back, a recording restarted): without a new
  // anchor the second part would be due at once, all of it; with one it keeps its own spacing.
  constexpr int64_t kBackJumpUs = 1000000;
  if (anchored_ && event_log_utime + kBackJumpUs < position_) anchored_ = false;
  position_ = event_log_utime;
  if (paused_) {
    if (is_step_event) step_pending_ = false;
    return;
  }
  if (!anchored_) {
    anchor_log_ = event_log_utime;
    anchor_wall_ = now_wall;
    anchored_ = true;
  }
}

void ReplayPacer::anchor(int64_t now_wall) {
  anchor_log_ = position_;
  anchor_wall_ = now_wall;
  anchored_ = position_ != 0;
}

void ReplayPacer::play(int64_t now_wall) {
  if (paused_) anchor(now_wall);  // resume from where it stopped, not where the wall clock went
  paused_ = false;
  step_pending_ = false;
}

void ReplayPacer::pause() { paused_ = true; }

void ReplayPacer::step() {
  paused_ = true;
  step_pending_ = true;
}

void ReplayPacer::set_speed(double speed, int64_t now_wall) {
  speed_ = checked_speed(speed);
  if (!paused_) anchor(now_wall);
}

ReplayCommand replay_command_from_name(const std::string& name) {
  if (name == "play") return ReplayCommand::kPlay;
  if (name == "pause") return ReplayCommand::kPause;
  if (name == "step") return ReplayCommand::kStep;
  if (name == "speed") return ReplayCommand::kSpeed;
  throw std::invalid_argument("unknown replay command '" + name + "' (play, pause, step, speed)");
}

std::string replay_command_name(ReplayCommand command) {
  switch (command) {
    case ReplayCommand::kPlay: return "play";
    case ReplayCommand::kPause: return "pause";
    case ReplayCommand::kStep: return "step";
    case ReplayCommand::kSpeed: return "speed";
  }
  return "?";
}

}  // namespace nudge::viewer
