#include "nudge/bus/viewer_convert.hpp"

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <stdexcept>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/decode.hpp"

namespace nudge::bus {

viewer::StateEntry state_entry_of(const supervisor_state_t& msg) {
  viewer::StateEntry entry;
  entry.utime = msg.utime;
  entry.run_id = msg.run_id;
  entry.state = msg.state_name;
  entry.attempt = msg.attempt;
  entry.reason = msg.reason;
  entry.segmented = msg.segmented;
  entry.failed_attempts = msg.failed_attempts;
  // The target is the attempt's: before the first attempt there is none.
  entry.has_target = msg.attempt > 0;
  std::copy(msg.target, msg.target + 3, entry.target);
  return entry;
}

namespace {

std::string process_state_name(int8_t state) {
  switch (state) {
    case process_info_t::STATE_RUNNING: return "running";
    case process_info_t::STATE_BACKOFF: return "restarting";
    case process_info_t::STATE_EXITED: return "exited";
    case process_info_t::STATE_STOPPING: return "stopping";
    case process_info_t::STATE_STOPPED: return "stopped";
  }
  return "state " + std::to_string(state);
}

}  // namespace

std::vector<viewer::ProcessRow> process_rows_of(const process_status_t& msg) {
  std::vector<viewer::ProcessRow> rows;
  for (const process_info_t& p : msg.processes) {
    viewer::ProcessRow row;
    row.name = p.name;
    row.state = process_state_name(p.state);
    row.log = p.log;
    row.pid = p.pid;
    row.restarts = p.restarts;
    row.last_exit_code = p.last_exit_code;
    row.uptime_s = p.uptime_s;
    row.restart_in_s = p.restart_in_s;
    rows.push_back(row);
  }
  return rows;
}

std::vector<viewer::StateEntry> supervisor_states_in_log(const std::string& log_path) {
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw std::runtime_error("cannot read the run's LCM log " + log_path);
  viewer::StateTimeline timeline(100000);
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != channel::SUPERVISOR_STATE) continue;
    supervisor_state_t msg;
    if (!decode_message(e->data, static_cast<int>(e->datalen), &msg).empty()) continue;
    timeline.observe(state_entry_of(msg));
  }
  return {timeline.entries().begin(), timeline.entries().end()};
}

}  // namespace nudge::bus
