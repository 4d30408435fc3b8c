#include "nudge/bus/process_status_convert.hpp"

namespace nudge::bus {

int8_t to_message(launcher::ProcessState state) {
  switch (state) {
    case launcher::ProcessState::kRunning: return process_info_t::STATE_RUNNING;
    case launcher::ProcessState::kBackoff: return process_info_t::STATE_BACKOFF;
    case launcher::ProcessState::kExited: return process_info_t::STATE_EXITED;
    case launcher::ProcessState::kStopping: return process_info_t::STATE_STOPPING;
    case launcher::ProcessState::kStopped: return process_info_t::STATE_STOPPED;
  }
  return process_info_t::STATE_STOPPED;
}

process_status_t to_message(const std::vector<launcher::ProcessInfo>& processes, int64_t utime,
                            const std::string& config_path) {
  process_status_t msg{};
  msg.utime = utime;
  msg.config = config_path;
  for (const launcher::ProcessInfo& p : processes) {
    process_info_t info{};
    info.name = p.name;
    info.pid = p.pid;
    info.state = to_message(p.state);
    info.restarts = p.restarts;
    info.last_exit_code = p.last_exit_code;
    info.uptime_s = p.uptime_s;
    info.restart_in_s = p.restart_in_s;
    info.log = p.log;
    msg.processes.push_back(info);
  }
  msg.num_processes = static_cast<int32_t>(msg.processes.size());
  return msg;
}

}  // namespace nudge::bus
