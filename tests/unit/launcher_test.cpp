// nudge_launcher: the launch file, the restart back-off, and a group of real (shell) processes:
// logs, restarts after a crash, restart policies, and a stop that kills what ignores SIGINT.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include "nudge/launcher/config.hpp"
#include "nudge/launcher/process_group.hpp"
#include "nudge/timing.hpp"

using namespace nudge::launcher;

namespace {

std::string temp_dir(const std::string& name) {
  const std::string dir = testing::TempDir() + "launcher_" + name + "_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  return dir;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

ProcessSpec shell(const std::string& name, const std::string& script, RestartPolicy restart = RestartPolicy::kAlways) {
  ProcessSpec spec;
  spec.name = name;
  spec.command = {"/bin/sh", "-c", script};
  spec.lcm_url_flag = "";
  spec.restart = restart;
  return spec;
}

// Polls the group until `done` holds or 10 s pass (a condition with a deadline, not a timing).
template <typename Done>
bool poll_until(ProcessGroup& group, Done done) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (std::chrono::steady_clock::now() < end) {
    group.poll(nudge::wall_utime());
    if (done()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return false;
}

}  // namespace

TEST(LaunchConfig, ReadsProcessesUrlBackoffAndPolicies) {
  const LaunchConfig c = parse_launch_config(R"({
    "lcm_url": "udpm://239.255.76.67:7668?ttl=0", "log_dir": "/tmp/x", "stop_timeout_s": 2,
    "backoff": {"initial_s": 0.25, "max_s": 4},
    "processes": [{"name": "symmetry", "command": ["build/bin/nudge-symmetry", "--lines", "5"]},
                  {"name": "logger", "command": ["lcm-logger", "-q", "x.lcmlog"], "lcm_url_flag": "--lcm-url=",
                   "restart": "on-failure"}]})",
                                             "test.json");
  EXPECT_EQ(c.lcm_url, "udpm://239.255.76.67:7668?ttl=0");
  EXPECT_EQ(c.stop_timeout_s, 2);
  EXPECT_EQ(c.backoff.initial_s, 0.25);
  EXPECT_EQ(c.backoff.stable_s, 10) << "default";
  ASSERT_EQ(c.processes.size(), 2u);
  EXPECT_EQ(c.processes[1].restart, RestartPolicy::kOnFailure);
  EXPECT_EQ(command_line(c.processes[0], c.lcm_url),
            (std::vector<std::string>{"build/bin/nudge-symmetry", "--lines", "5", "--lcm-url", c.lcm_url}));
  EXPECT_EQ(command_line(c.processes[1], c.lcm_url).back(), "--lcm-url=" + c.lcm_url);
}

TEST(LaunchConfig, ErrorsNameTheFileAndTheField) {
  const auto error_of = [](const std::string& text) {
    try {
      parse_launch_config(text, "bad.json");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("{").find("bad.json: not JSON"), std::string::npos);
  EXPECT_NE(error_of(R"({"processes": []})").find("processes must be a non-empty array"), std::string::npos);
  EXPECT_NE(error_of(R"({"processes": [{"command": ["a"]}]})").find("processes[0].name is missing"), std::string::npos);
  EXPECT_NE(error_of(R"({"processes": [{"name": "a", "command": []}]})").find("processes[0].command"), std::string::npos);
  EXPECT_NE(error_of(R"({"processes": [{"name": "a", "command": ["x"]}, {"name": "a", "command": ["y"]}]})")
                .find("two processes are named 'a'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"processes": [{"name": "a", "command": ["x"], "restart": "sometimes"}]})")
                .find("processes[0].restart is 'sometimes'"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"backoff": {"max_s": -1}, "processes": [{"name": "a", "command": ["x"]}]})")
                .find("backoff.max_s must be >= 0"),
            std::string::npos);
  EXPECT_THROW(load_launch_config("/nonexistent/launch.json"), std::runtime_error);
}

TEST(RestartDelay, DoublesAfterEachQuickFailureUpToTheMaximum) {
  Backoff b;
  b.initial_s = 0.5;
  b.max_s = 3;
  EXPECT_EQ(restart_delay_s(1, b), 0.5);
  EXPECT_EQ(restart_delay_s(2, b), 1.0);
  EXPECT_EQ(restart_delay_s(3, b), 2.0);
  EXPECT_EQ(restart_delay_s(4, b), 3.0);
  EXPECT_EQ(restart_delay_s(100, b), 3.0);
}

TEST(ProcessGroup, RestartsACrashingProcessWithBackoffAndLogsEachRun) {
  LaunchConfig config;
  config.log_dir = temp_dir("crash");
  config.backoff.initial_s = 0.05;
  config.backoff.max_s = 0.2;
  config.processes = {shell("crasher", "echo run; exit 3"), shell("steady", "echo up; exec sleep 30")};
  ProcessGroup group(config);
  group.start(nudge::wall_utime());
  ASSERT_TRUE(poll_until(group, [&] { return group.status(nudge::wall_utime())[0].restarts >= 3; }));
  const auto status = group.status(nudge::wall_utime());
  EXPECT_EQ(status[0].last_exit_code, 3);
  EXPECT_EQ(status[1].state, ProcessState::kRunning);
  EXPECT_EQ(status[1].restarts, 0);
  EXPECT_GT(status[1].pid, 0);
  EXPECT_EQ(group.stop(), 0) << "sleep ends on SIGINT";
  EXPECT_EQ(group.status(nudge::wall_utime())[1].state, ProcessState::kStopped);
  const std::string log = read_file(config.log_dir + "/crasher.log");
  EXPECT_GE(std::count(log.begin(), log.end(), '\n'), 3) << "one line per run, appended:\n" << log;
  EXPECT_EQ(read_file(config.log_dir + "/steady.log"), "up\n");
}

TEST(ProcessGroup, PoliciesDecideWhatEndsForGoodAndAMissingProgramIsLogged) {
  LaunchConfig config;
  config.log_dir = temp_dir("policy");
  config.backoff.initial_s = 0.05;
  ProcessSpec missing;
  missing.name = "missing";
  missing.command = {"/nonexistent/program"};
  missing.lcm_url_flag = "";
  missing.restart = RestartPolicy::kNever;
  config.processes = {shell("done", "exit 0", RestartPolicy::kOnFailure), shell("never", "exit 1", RestartPolicy::kNever),
                      missing};
  ProcessGroup group(config);
  group.start(nudge::wall_utime());
  ASSERT_TRUE(poll_until(group, [&] {
    for (const auto& p : group.status(nudge::wall_utime()))
      if (p.state != ProcessState::kExited) return false;
    return true;
  }));
  const auto status = group.status(nudge::wall_utime());
  EXPECT_EQ(status[0].last_exit_code, 0);
  EXPECT_EQ(status[1].last_exit_code, 1);
  EXPECT_EQ(status[2].last_exit_code, 127);
  for (const auto& p : status) EXPECT_EQ(p.restarts, 0) << p.name;
  EXPECT_NE(read_file(config.log_dir + "/missing.log").find("cannot run the program: /nonexistent/program"),
            std::string::npos);
}

TEST(ProcessGroup, StopKillsWhatIgnoresSigint) {
  LaunchConfig config;
  config.log_dir = temp_dir("stop");
  config.stop_timeout_s = 0.3;
  config.processes = {shell("stubborn", "trap '' INT; echo ready; while true; do sleep 0.05; done")};
  ProcessGroup group(config);
  group.start(nudge::wall_utime());
  ASSERT_TRUE(poll_until(group, [&] { return read_file(config.log_dir + "/stubborn.log") == "ready\n"; }));
  EXPECT_EQ(group.stop(), 1);
  const auto status = group.status(nudge::wall_utime());
  EXPECT_EQ(status[0].state, ProcessState::kStopped);
  EXPECT_EQ(status[0].last_exit_code, 128 + 9);
}
