// supervisor_state_t -> viewer::StateEntry, live and from a run's log (nudge_bus_viewer).
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/viewer_convert.hpp"
#include "nudge/test/lcm_log.hpp"

using namespace nudge;

namespace {

supervisor_state_t state(int64_t utime, const std::string& name, int attempt, const std::string& reason) {
  supervisor_state_t msg{};
  msg.utime = utime;
  msg.run_id = "r7";
  msg.state_name = name;
  msg.attempt = attempt;
  msg.reason = reason;
  msg.segmented = attempt > 1 ? 1 : 0;
  msg.failed_attempts = 0;
  msg.target[0] = 0.3, msg.target[1] = -0.02, msg.target[2] = 0.01;
  return msg;
}

}  // namespace

TEST(BusViewer, StateEntryCarriesEveryFieldAndATargetOnlyDuringAnAttempt) {
  const viewer::StateEntry entry = bus::state_entry_of(state(42, "NUDGE", 2, "nudging candidate 1"));
  EXPECT_EQ(entry.utime, 42);
  EXPECT_EQ(entry.run_id, "r7");
  EXPECT_EQ(entry.state, "NUDGE");
  EXPECT_EQ(entry.attempt, 2);
  EXPECT_EQ(entry.reason, "nudging candidate 1");
  EXPECT_EQ(entry.segmented, 1);
  EXPECT_TRUE(entry.has_target);
  EXPECT_DOUBLE_EQ(entry.target[0], 0.3);
  EXPECT_DOUBLE_EQ(entry.target[2], 0.01);
  EXPECT_FALSE(bus::state_entry_of(state(1, "FIND_CANDIDATES", 0, "")).has_target);
}

TEST(BusViewer, StatesInALogAreItsTransitionsWithRepeatsFoldedAndMalformedOnesSkipped) {
  const std::string path = testing::TempDir() + "/states_" + std::to_string(getpid()) + ".lcmlog";
  {
    test::LogWriter log(path);
    log.write(1000, bus::channel::SUPERVISOR_STATE, state(1000, "FIND_CANDIDATES", 0, "surveying"));
    log.write(2000, bus::channel::SUPERVISOR_STATE, state(2000, "FIND_CANDIDATES", 0, "surveying"));  // 1 Hz repeat
    log.raw(2500, bus::channel::SUPERVISOR_STATE, {1, 2, 3});                                          // malformed
    log.write(2600, "HEARTBEAT_ELSEWHERE", state(2600, "NOT_A_STATE", 9, ""));                         // other channel
    log.write(3000, bus::channel::SUPERVISOR_STATE, state(3000, "NUDGE", 1, "nudging candidate 2"));
    log.write(9000, bus::channel::SUPERVISOR_STATE, state(9000, "DONE", 1, "no candidate left"));
  }
  const std::vector<viewer::StateEntry> states = bus::supervisor_states_in_log(path);
  ASSERT_EQ(states.size(), 3u);
  EXPECT_EQ(states[0].state, "FIND_CANDIDATES");
  EXPECT_EQ(states[1].state, "NUDGE");
  EXPECT_EQ(states[1].reason, "nudging candidate 2");
  EXPECT_EQ(states[2].state, "DONE");
  EXPECT_EQ(states[2].utime, 9000);
  std::remove(path.c_str());
}

TEST(BusViewer, AnUnreadableLogIsNamed) {
  try {
    bus::supervisor_states_in_log("/nonexistent/run.lcmlog");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/run.lcmlog"), std::string::npos);
  }
}

TEST(BusViewer, ProcessRowsCarryEveryFieldAndNameTheStateAsThePageDoes) {
  process_status_t msg{};
  const int8_t codes[] = {process_info_t::STATE_RUNNING, process_info_t::STATE_BACKOFF, process_info_t::STATE_EXITED,
                          process_info_t::STATE_STOPPING, process_info_t::STATE_STOPPED, 99};
  for (int8_t code : codes) {
    process_info_t p{};
    p.name = "p" + std::to_string(code);
    p.state = code;
    p.log = "logs/" + p.name + ".log";
    p.pid = 100 + code;
    p.restarts = code;
    p.last_exit_code = -code;
    p.uptime_s = 0.5 * code;
    p.restart_in_s = 0.25 * code;
    msg.processes.push_back(p);
  }
  msg.num_processes = static_cast<int32_t>(msg.processes.size());
  const std::vector<viewer::ProcessRow> rows = bus::process_rows_of(msg);
  ASSERT_EQ(rows.size(), 6u);
  const std::vector<std::string> names = {"running", "restarting", "exited", "stopping", "stopped", "state 99"};
  for (size_t i = 0; i < rows.size(); ++i) {
    const int code = codes[i];
    EXPECT_EQ(rows[i].state, names[i]);
    EXPECT_EQ(rows[i].name, "p" + std::to_string(code));
    EXPECT_EQ(rows[i].log, "logs/p" + std::to_string(code) + ".log");
    EXPECT_EQ(rows[i].pid, 100 + code);
    EXPECT_EQ(rows[i].restarts, code);
    EXPECT_EQ(rows[i].last_exit_code, -code);
    EXPECT_DOUBLE_EQ(rows[i].uptime_s, 0.5 * code);
    EXPECT_DOUBLE_EQ(rows[i].restart_in_s, 0.25 * code);
  }
}
