// nudge-launch as a binary: it runs the processes of a launch file, restarts the one that
// crashes, publishes their status on PROCESS_STATUS, and on SIGINT stops them all and exits 0.
// Its bus is LCM's in-process provider in, a log file out: no network.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "nudge/bus/channels.hpp"
#include "nudge/process_status_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/process.hpp"
#include "nudge/test/run_service.hpp"

using nudge::test::Process;

TEST(LaunchService, RunsRestartsReportsAndStopsTheSet) {
  const std::string dir = nudge::test::temp_path("launch");
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string pid_file = dir + "/steady.pid";
  std::ofstream(dir + "/launch.json") << R"({"log_dir": ")" << dir << R"(/logs", "backoff": {"initial_s": 0.1},
    "processes": [
      {"name": "steady", "command": ["/bin/sh", "-c", "echo $$ > )" << pid_file << R"(; exec sleep 60"], "lcm_url_flag": ""},
      {"name": "crasher", "command": ["/bin/sh", "-c", "exit 4"], "lcm_url_flag": ""}]})";
  const std::string out = dir + "/status.lcmlog";
  Process launch({nudge::test::bin_dir() + "/nudge-launch", "--lcm-in", "memq://", "--lcm-out",
                  "file://" + out + "?mode=w", dir + "/launch.json"},
                 dir + "/launch.log");
  ASSERT_TRUE(launch.started());
  // Until the steady process has written its pid and the crasher has been restarted (its log).
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (std::chrono::steady_clock::now() < end && !std::filesystem::exists(pid_file))
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));
  launch.signal(SIGINT);
  EXPECT_EQ(launch.wait_exit(15), 0);
  pid_t steady = 0;
  std::ifstream(pid_file) >> steady;
  ASSERT_GT(steady, 0);
  EXPECT_NE(kill(steady, 0), 0) << "the launched process outlived the launcher";

  const auto statuses = nudge::test::read_messages<nudge::process_status_t>(out, nudge::bus::channel::PROCESS_STATUS);
  ASSERT_GE(statuses.size(), 2u);
  const auto& first = statuses.front();
  ASSERT_EQ(first.num_processes, 2);
  EXPECT_EQ(first.processes[0].name, "steady");
  EXPECT_EQ(first.processes[0].state, int8_t{nudge::process_info_t::STATE_RUNNING});
  const auto& last = statuses.back();
  EXPECT_EQ(last.processes[0].state, int8_t{nudge::process_info_t::STATE_STOPPED}) << "the status after the stop";
  EXPECT_GE(last.processes[1].restarts, 1) << "the crasher was restarted";
  EXPECT_EQ(last.processes[1].last_exit_code, 4);

  // A bad launch file is named with its field, exit code 1.
  std::ofstream(dir + "/bad.json") << R"({"processes": [{"name": "a"}]})";
  const auto bad = nudge::test::run_capturing(nudge::test::bin_dir() + "/nudge-launch --lcm-url memq:// " + dir + "/bad.json");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("bad.json: processes[0].command"), std::string::npos) << bad.err;
}
