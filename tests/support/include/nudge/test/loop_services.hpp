#pragma once
// The services of the autonomous segmentation loop (world, camera, symmetry, triangulation, arm;
// the learner when a run learns) as the integration tests run them: each its own process on the
// simulated clock, its log NAME.log in the test's folder. The supervisor is the test's own.
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "nudge/test/private_network.hpp"
#include "nudge/test/process.hpp"

namespace nudge::test {

struct LoopSetup {
  std::string dir;          // the services' logs (NAME.log) and the learner's object database (objects/)
  std::string scene;        // the simulated scene (the camera's and the world's)
  std::string calibration;  // the stereo rig (triangulation's)
  std::string url = kPrivateLcmUrl;
  std::vector<std::string> world_flags;  // added to the world's command line (e.g. --tool auto)
};

// The command line of one of the loop's services: symmetry, camera, triangulation, arm, world or
// learner; empty for any other name.
std::vector<std::string> loop_service_command(const std::string& service, const LoopSetup& setup);

// The supervisor's command line for the run `run_id` on the loop's bus: the setup's calibration,
// the run's files in setup.dir/run_id, ARM_COMMAND sequence numbers from 1000; `flags` added.
std::vector<std::string> loop_supervisor_command(const LoopSetup& setup, const std::string& run_id,
                                                 const std::vector<std::string>& flags = {});

// The same supervisor replaying a run's LCM log `log` as fast as it reads it, publishing into the
// log `out_log` (the regression check of replays: the same decisions from the log alone).
std::vector<std::string> replay_supervisor_command(const LoopSetup& setup, const std::string& log,
                                                   const std::string& out_log, const std::string& run_id,
                                                   const std::vector<std::string>& flags = {});

class LoopServices {
 public:
  explicit LoopServices(LoopSetup setup) : setup_(std::move(setup)) {}
  LoopServices(const LoopServices&) = delete;
  LoopServices& operator=(const LoopServices&) = delete;
  ~LoopServices() { stop_all(); }

  // Starts symmetry, camera, triangulation, arm and the `extra` services, gives them 3 s to
  // subscribe before the world's first state (the camera builds its scene first), then starts the
  // world. Returns the services that could not start (none: empty).
  std::vector<std::string> start_all(const std::vector<std::string>& extra = {});

  // Starts one service (again: a process still running under that name is stopped first). False
  // when it could not start.
  bool start(const std::string& service);

  // The running service's process (started by start or start_all).
  Process& operator[](const std::string& service) { return *processes_.at(service); }

  // Stops every service (SIGINT, then SIGKILL after 5 s), the last started first.
  void stop_all();

 private:
  LoopSetup setup_;
  std::map<std::string, std::unique_ptr<Process>> processes_;
  std::vector<std::string> order_;  // the names in the order they were first started
};

}  // namespace nudge::test
