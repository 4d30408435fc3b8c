#include "nudge/test/loop_services.hpp"

#include <unistd.h>

#include <algorithm>

namespace nudge::test {

namespace {

const std::string kBin = NUDGE_BIN_DIR;

std::vector<std::string> supervisor_command(const LoopSetup& setup, const std::vector<std::string>& bus_flags,
                                            const std::string& run_id, const std::vector<std::string>& flags) {
  std::vector<std::string> argv = {kBin + "/nudge-supervisor"};
  argv.insert(argv.end(), bus_flags.begin(), bus_flags.end());
  argv.insert(argv.end(), {"--calibration", setup.calibration, "--out", setup.dir, "--run-id", run_id, "--first-seq", "1000"});
  argv.insert(argv.end(), flags.begin(), flags.end());
  return argv;
}

}  // namespace

std::vector<std::string> loop_service_command(const std::string& service, const LoopSetup& setup) {
  const std::string& url = setup.url;
  if (service == "learner") return {kBin + "/nudge-learner", "--lcm-url", url, "--db", setup.dir + "/objects"};
  if (service == "symmetry")
    return {kBin + "/nudge-symmetry", "--lcm-url", url, "--lines", "5", "--theta-min", "-25", "--theta-max", "25",
            "--once-per-row", "--mirror-tolerance", "15"};
  if (service == "camera")
    return {kBin + "/nudge-camera", "--lcm-url", url, "--source", "sim", "--scene", setup.scene, "--snapshots"};
  if (service == "triangulation")
    return {kBin + "/nudge-triangulation", "--lcm-url", url, "--calibration", setup.calibration};
  if (service == "arm") return {kBin + "/nudge-arm", "--lcm-url", url, "--backend", "sim", "--clock", "sim"};
  if (service == "world") {
    std::vector<std::string> argv = {kBin + "/nudge-world", "--lcm-url", url, "--scene", setup.scene,
                                     "--realtime-factor", "1", "--rate", "10"};
    argv.insert(argv.end(), setup.world_flags.begin(), setup.world_flags.end());
    return argv;
  }
  return {};
}

std::vector<std::string> loop_supervisor_command(const LoopSetup& setup, const std::string& run_id,
                                                 const std::vector<std::string>& flags) {
  return supervisor_command(setup, {"--lcm-url", setup.url}, run_id, flags);
}

std::vector<std::string> replay_supervisor_command(const LoopSetup& setup, const std::string& log,
                                                   const std::string& out_log, const std::string& run_id,
                                                   const std::vector<std::string>& flags) {
  return supervisor_command(setup, {"--lcm-in", "file://" + log + "?speed=0", "--lcm-out", "file://" + out_log + "?mode=w"},
                            run_id, flags);
}

std::vector<std::string> LoopServices::start_all(const std::vector<std::string>& extra) {
  std::vector<std::string> first = {"symmetry", "camera", "triangulation", "arm"};
  first.insert(first.end(), extra.begin(), extra.end());
  std::vector<std::string> failed;
  for (const std::string& service : first)
    if (!start(service)) failed.push_back(service);
  sleep(3);
  if (!start("world")) failed.push_back("world");
  return failed;
}

bool LoopServices::start(const std::string& service) {
  const std::vector<std::string> argv = loop_service_command(service, setup_);
  if (argv.empty()) return false;
  if (std::find(order_.begin(), order_.end(), service) == order_.end()) order_.push_back(service);
  processes_[service].reset();  // the earlier process stops before its successor starts
  processes_[service] = std::make_unique<Process>(argv, setup_.dir + "/" + service + ".log");
  return processes_[service]->started();
}

void LoopServices::stop_all() {
  for (auto name = order_.rbegin(); name != order_.rend(); ++name) processes_[*name].reset();
}

}  // namespace nudge::test
