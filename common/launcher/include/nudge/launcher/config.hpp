#pragma once
// A launch file: which programs, with which arguments, on which LCM URL, and how to restart them.
//   {"lcm_url": "udpm://239.255.76.67:7667?ttl=0", "log_dir": "out/launch",
//    "backoff": {"initial_s": 0.5, "max_s": 10, "stable_s": 10}, "stop_timeout_s": 5,
//    "processes": [{"name": "symmetry", "command": ["build/bin/nudge-symmetry", "--lines", "5"]},
//                  {"name": "logger", "command": ["lcm-logger", "-q", "out/x.lcmlog"],
//                   "lcm_url_flag": "--lcm-url=", "restart": "on-failure"}]}
// Relative paths (commands, log_dir) are taken from the current directory.
#include <string>
#include <vector>

namespace nudge::launcher {

enum class RestartPolicy { kAlways, kOnFailure, kNever };

struct Backoff {
  double initial_s = 0.5;  // the first restart's delay, doubled after each quick failure
  double max_s = 10;
  double stable_s = 10;  // a run this long resets the delay
};

struct ProcessSpec {
  std::string name;
  std::vector<std::string> command;  // argv; command[0] is looked up on PATH when it has no '/'
  // The launch file's LCM URL is passed as "--lcm-url URL" (nudge services), or with a flag of
  // the program's own: "--lcm-url=" (lcm-logger) joins flag and URL; "" passes none.
  std::string lcm_url_flag = "--lcm-url";
  RestartPolicy restart = RestartPolicy::kAlways;
};

struct LaunchConfig {
  std::string lcm_url = "udpm://239.255.76.67:7667?ttl=0";
  std::string log_dir = "out/launch";
  Backoff backoff;
  double stop_timeout_s = 5;
  std::vector<ProcessSpec> processes;
};

// Throws std::runtime_error naming the file and the field: unreadable, not JSON, a process with
// no name or command, two with one name, an unknown restart policy, a negative time.
LaunchConfig load_launch_config(const std::string& path);
// The same from text; `source` names it in errors.
LaunchConfig parse_launch_config(const std::string& text, const std::string& source);

// The argv a process runs with: its command plus the LCM URL flag.
std::vector<std::string> command_line(const ProcessSpec& spec, const std::string& lcm_url);

// The delay before restarting a process that failed `quick_failures` times in a row (>= 1):
// initial_s, doubled each time, at most max_s.
double restart_delay_s(int quick_failures, const Backoff& backoff);

}  // namespace nudge::launcher
