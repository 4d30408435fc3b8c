// launch: runs the set of processes of one launch file (common/launcher/config.hpp): a log file
// per process, restart with back-off when one ends, a clean stop of everything on SIGINT/SIGTERM
// (Ctrl-C: SIGINT to each, SIGKILL to those still running after stop_timeout_s), and the status
// of the set on PROCESS_STATUS (process_status_t) once a second and at every change, so that the
// viewer (or lcm-spy) shows it. docs/operator.md says why it is not supervisord.
#include "nudge/bus/channels.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/launcher/config.hpp"
#include "nudge/launcher/process_group.hpp"
#include "nudge/log.hpp"
#include "nudge/process_status_t.hpp"
#include "nudge/timing.hpp"

using namespace nudge;

namespace {

int8_t state_code(launcher::ProcessState state) {
  switch (state) {
    case launcher::ProcessState::kRunning: return process_info_t::STATE_RUNNING;
    case launcher::ProcessState::kBackoff: return process_info_t::STATE_BACKOFF;
    case launcher::ProcessState::kExited: return process_info_t::STATE_EXITED;
    case launcher::ProcessState::kStopping: return process_info_t::STATE_STOPPING;
    case launcher::ProcessState::kStopped: return process_info_t::STATE_STOPPED;
  }
  return process_info_t::STATE_STOPPED;
}

process_status_t status_message(const launcher::ProcessGroup& group, const std::string& config_path) {
  process_status_t msg{};
  msg.utime = wall_utime();
  msg.config = config_path;
  for (const launcher::ProcessInfo& p : group.status(msg.utime)) {
    process_info_t info{};
    info.name = p.name;
    info.pid = p.pid;
    info.state = state_code(p.state);
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

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("launch", [&] {
    bus::Service service("launch", "Runs the services of a launch file; their status on PROCESS_STATUS.");
    auto& f = service.flags();
    f.set_positional("LAUNCH_FILE", "the JSON launch file (docs/operator.md)");
    if (!service.parse(argc, argv)) return 0;
    if (f.positional().size() != 1) throw FlagError("give exactly one LAUNCH_FILE");
    const std::string path = f.positional()[0];
    launcher::LaunchConfig config = launcher::load_launch_config(path);  // throws naming file and field
    // The launcher's own status goes on the launch file's bus unless a flag names another.
    const bool own_url = f.given("lcm-url") || f.given("lcm-in") || f.given("lcm-out");
    if (own_url) service.start();
    else service.start(config.lcm_url, "");

    launcher::ProcessGroup group(config);
    group.start(wall_utime());
    service.publish(bus::channel::PROCESS_STATUS, status_message(group, path));
    int64_t next_status = wall_utime() + 1000000;
    const int code = service.run([&] {
      const int64_t now = wall_utime();
      if (group.poll(now) || now >= next_status) {
        service.publish(bus::channel::PROCESS_STATUS, status_message(group, path));
        next_status = now + 1000000;
      }
      return 50;
    });
    log::info() << "stopping " << config.processes.size() << " processes";
    const int killed = group.stop();
    service.publish(bus::channel::PROCESS_STATUS, status_message(group, path));
    log::info() << "all stopped" << (killed ? " (" + std::to_string(killed) + " killed)" : std::string());
    return code;
  });
}
