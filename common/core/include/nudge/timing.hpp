#pragma once
#include <chrono>
#include <cstdint>

namespace nudge {

// Monotonic stopwatch for measuring phases of an algorithm (milliseconds).
class Stopwatch {
 public:
  Stopwatch() : start_(Clock::now()) {}
  void restart() { start_ = Clock::now(); }
  double elapsed_ms() const {
    return std::chrono::duration<double, std::milli>(Clock::now() - start_).count();
  }
  // Milliseconds since the last lap (or construction), and starts a new lap.
  double lap_ms() {
    const auto now = Clock::now();
    const double ms = std::chrono::duration<double, std::milli>(now - start_).count();
    start_ = now;
    return ms;
  }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point start_;
};

// Wall-clock time in microseconds since the epoch (for heartbeats and live capture stamps).
int64_t wall_utime();

// The calling thread's CPU time, ms: what a computation on it cost, whatever else the (shared)
// host ran meanwhile.
double thread_cpu_ms();

}  // namespace nudge
