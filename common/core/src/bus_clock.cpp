#include "nudge/bus_clock.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

namespace nudge {

ClockSource parse_clock_source(const std::string& name, bool input_is_log) {
  if (name == "auto") return input_is_log ? ClockSource::Log : ClockSource::Wall;
  if (name == "wall") return ClockSource::Wall;
  if (name == "sim") return ClockSource::Sim;
  if (name == "log") return ClockSource::Log;
  throw std::invalid_argument("clock must be auto, wall, sim or log, not '" + name + "'");
}

std::string clock_source_name(ClockSource source) {
  switch (source) {
    case ClockSource::Wall: return "wall";
    case ClockSource::Sim: return "sim";
    case ClockSource::Log: return "log";
  }
  return "?";
}

BusClock::BusClock(ClockSource source, WallClock wall) : source_(source), wall_(std::move(wall)) {
  if (!wall_) throw std::invalid_argument("BusClock without a wall clock");
}

std::optional<int64_t> BusClock::on_message(int64_t utime, Stamp stamp) {
  switch (source_) {
    case ClockSource::Wall: return move_to(wall_());
    case ClockSource::Sim:
      if (stamp != Stamp::Simulated) return std::nullopt;
      return move_to(utime);
    case ClockSource::Log:
      if (stamp != Stamp::Sender) return std::nullopt;
      return move_to(utime);
  }
  return std::nullopt;
}

std::optional<int64_t> BusClock::on_timer() {
  if (source_ != ClockSource::Wall) return std::nullopt;
  return move_to(wall_());
}

int64_t BusClock::deadline_time() const {
  if (deadlines_on_message_time()) return now_.value_or(0);
  return wall_();
}

int64_t BusClock::move_to(int64_t utime) {
  if (!now_ || utime > *now_) now_ = utime;
  return *now_;
}

double LogTimeline::seconds(int64_t utime) {
  if (!origin_) origin_ = utime < kWallClockUtime ? 0 : utime;
  const double seconds = 1e-6 * static_cast<double>(utime - *origin_);
  if (seconds > kMaxSeconds) {
    throw std::invalid_argument("utime " + std::to_string(utime) + " is " + std::to_string(seconds) +
                                " s after the log's origin: not on the same clock");
  }
  return seconds;
}

Pacer::Pacer(double factor, WallClock wall) : factor_(factor), wall_(std::move(wall)) {
  if (!(factor > 0) || !std::isfinite(factor)) throw std::invalid_argument("pacing factor must be positive and finite");
  if (!wall_) throw std::invalid_argument("Pacer without a wall clock");
}

double Pacer::target(double sim_time) {
  const int64_t now = wall_();
  if (!anchored_) {
    anchor_wall_ = now;
    anchor_sim_ = sim_time;
    anchored_ = true;
  }
  double t = anchor_sim_ + factor_ * 1e-6 * static_cast<double>(now - anchor_wall_);
  if (t - sim_time > kMaxLag) {
    ++slips_;
    anchor_wall_ = now;
    anchor_sim_ = sim_time;
    t = sim_time;
  }
  return t;
}

int Pacer::wait_ms(double due, double sim_target) const {
  return static_cast<int>(std::clamp(std::ceil(1e3 * (due - sim_target) / factor_), 0.0, 20.0));
}

}  // namespace nudge
