// launch: runs the set of processes of one launch file (common/launcher/config.hpp): a log file
// per process, restart with back-off when one ends, a clean stop of everything on SIGINT/SIGTERM
// (Ctrl-C: SIGINT to each, SIGKILL to those still running after stop_timeout_s), and the status
// of the set on PROCESS_STATUS (process_status_t) once a second and at every change, so that the
// viewer (or lcm-spy) shows it. docs/operator.md says why it is not supervisord.
#include "nudge/bus/channels.hpp"
#include "nudge/bus/process_status_convert.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/launcher/config.hpp"
#include "nudge/launcher/process_group.hpp"
#include "nudge/log.hpp"
#include "nudge/process_status_t.hpp"
#include "nudge/timing.hpp"

using namespace nudge;

namespace {

process_status_t status_message(const launcher::ProcessGroup& group, const std::string& config_path) {
  const int64_t now = wall_utime();
  return bus::to_message(group.status(now), now, config_path);
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
