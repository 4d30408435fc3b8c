#pragma once
// The processes of a launch file, kept running: each started in its own process group with its
// standard output and error appended to LOG_DIR/NAME.log; one that ends is restarted after a
// back-off (restart_delay_s) as its restart policy says; stop() sends SIGINT to every one, then
// SIGKILL to those still running after the stop timeout. Single-threaded: the owner calls poll()
// regularly (it reaps children without blocking).
#include <sys/types.h>

#include <cstdint>
#include <string>
#include <vector>

#include "nudge/launcher/config.hpp"

namespace nudge::launcher {

enum class ProcessState { kRunning, kBackoff, kExited, kStopping, kStopped };
std::string to_string(ProcessState state);

struct ProcessInfo {
  std::string name, log;
  pid_t pid = 0;
  ProcessState state = ProcessState::kStopped;
  int restarts = 0;
  int last_exit_code = -1;  // 128 + N when killed by signal N
  double uptime_s = 0, restart_in_s = 0;
};

class ProcessGroup {
 public:
  // Creates log_dir. Throws std::runtime_error naming it when it cannot.
  explicit ProcessGroup(LaunchConfig config);
  ~ProcessGroup();  // stops whatever still runs
  ProcessGroup(const ProcessGroup&) = delete;
  ProcessGroup& operator=(const ProcessGroup&) = delete;

  // Starts every process. A program that cannot be started is logged in its log file and counts
  // as a failed run (restarted with back-off).
  void start(int64_t now_utime);
  // Reaps ended processes and restarts those due. Returns whether any process changed state.
  bool poll(int64_t now_utime);
  // SIGINT to all, SIGKILL after the stop timeout; waits until every one has ended. Returns how
  // many had to be killed.
  int stop();

  std::vector<ProcessInfo> status(int64_t now_utime) const;
  const LaunchConfig& config() const { return config_; }

 private:
  struct Child {
    ProcessSpec spec;
    std::string log;
    pid_t pid = 0;
    ProcessState state = ProcessState::kStopped;
    int restarts = 0, quick_failures = 0, last_exit_code = -1;
    int64_t started_utime = 0, restart_at_utime = 0;
  };
  void launch(Child& child, int64_t now_utime);
  void ended(Child& child, int exit_code, int64_t now_utime);

  LaunchConfig config_;
  std::vector<Child> children_;
};

}  // namespace nudge::launcher
