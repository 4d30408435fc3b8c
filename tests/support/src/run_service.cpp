#include "nudge/test/run_service.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>

namespace nudge::test {

std::string bin_dir() { return NUDGE_BIN_DIR; }

std::string temp_path(const std::string& name) {
  return testing::TempDir() + "/" + std::to_string(::getpid()) + "_" + name;
}

int run_command(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

LogRun run_from_log(const std::string& program, const std::string& args, const std::string& in,
                    const std::string& out) {
  std::remove(out.c_str());
  LogRun run;
  // The URLs first, then `args`, which may end in a redirection.
  run.command = bin_dir() + "/" + program + " --lcm-in 'file://" + in + "?speed=0' --lcm-out 'file://" + out +
                "?mode=w' " + args;
  run.exit_code = run_command(run.command);
  if (::access(out.c_str(), R_OK) == 0) run.output = read_log(out);
  return run;
}

}  // namespace nudge::test
