// launcher::ProcessInfo -> process_status_t (nudge_bus_launcher): what nudge-launch publishes on
// PROCESS_STATUS.
#include <gtest/gtest.h>

#include <vector>

#include "nudge/bus/process_status_convert.hpp"

using namespace nudge;

TEST(BusLauncher, EveryProcessStateHasItsOwnCode) {
  EXPECT_EQ(bus::to_message(launcher::ProcessState::kRunning), +process_info_t::STATE_RUNNING);
  EXPECT_EQ(bus::to_message(launcher::ProcessState::kBackoff), +process_info_t::STATE_BACKOFF);
  EXPECT_EQ(bus::to_message(launcher::ProcessState::kExited), +process_info_t::STATE_EXITED);
  EXPECT_EQ(bus::to_message(launcher::ProcessState::kStopping), +process_info_t::STATE_STOPPING);
  EXPECT_EQ(bus::to_message(launcher::ProcessState::kStopped), +process_info_t::STATE_STOPPED);
}

TEST(BusLauncher, StatusCarriesEveryProcessAndField) {
  launcher::ProcessInfo symmetry;
  symmetry.name = "symmetry";
  symmetry.log = "out/launch/symmetry.log";
  symmetry.pid = 4242;
  symmetry.state = launcher::ProcessState::kRunning;
  symmetry.restarts = 2;
  symmetry.last_exit_code = 137;
  symmetry.uptime_s = 12.5;
  launcher::ProcessInfo camera;
  camera.name = "camera";
  camera.state = launcher::ProcessState::kBackoff;
  camera.restart_in_s = 0.75;

  const process_status_t msg = bus::to_message({symmetry, camera}, 1234567, "config/demo.json");
  EXPECT_EQ(msg.utime, 1234567);
  EXPECT_EQ(msg.config, "config/demo.json");
  ASSERT_EQ(msg.num_processes, 2);
  ASSERT_EQ(msg.processes.size(), 2u);
  const process_info_t& first = msg.processes[0];
  EXPECT_EQ(first.name, "symmetry");
  EXPECT_EQ(first.log, "out/launch/symmetry.log");
  EXPECT_EQ(first.pid, 4242);
  EXPECT_EQ(first.state, +process_info_t::STATE_RUNNING);
  EXPECT_EQ(first.restarts, 2);
  EXPECT_EQ(first.last_exit_code, 137);
  EXPECT_DOUBLE_EQ(first.uptime_s, 12.5);
  EXPECT_EQ(msg.processes[1].name, "camera");
  EXPECT_EQ(msg.processes[1].state, +process_info_t::STATE_BACKOFF);
  EXPECT_DOUBLE_EQ(msg.processes[1].restart_in_s, 0.75);
  EXPECT_EQ(msg.processes[1].last_exit_code, -1);
}

TEST(BusLauncher, NoProcessesIsAnEmptyStatus) {
  const process_status_t msg = bus::to_message(std::vector<launcher::ProcessInfo>{}, 5, "x.json");
  EXPECT_EQ(msg.num_processes, 0);
  EXPECT_TRUE(msg.processes.empty());
}
