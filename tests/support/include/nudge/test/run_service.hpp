#pragma once
// Running the programs under test: a service binary as a pure function from an input log to an
// output log (LCM's file provider, as fast as it reads), or any command line.
#include <string>
#include <vector>

#include "nudge/test/lcm_log.hpp"

namespace nudge::test {

// Where the build put the programs (build/bin).
std::string bin_dir();
// A path in the test's temporary directory that no other process uses (several build trees may
// run their tests at the same time). Every path handed out is removed (file or directory) when
// the test program ends with every test passed, unless NUDGE_KEEP_TEST_RUNS is set: a failed run
// keeps its logs to look at, a passed one leaves nothing behind.
std::string temp_path(const std::string& name);
// Runs a shell command. Returns its exit code, or -1 when it did not exit (killed by a signal).
int run_command(const std::string& command);

struct CommandOutput {
  int exit_code = -1;  // -1 when the command did not exit (killed by a signal)
  std::string out;     // its standard output
  std::string err;     // its standard error
};
// Runs a shell command capturing its standard output and error (the command must not redirect
// them itself).
CommandOutput run_capturing(const std::string& command);

struct LogRun {
  std::string command;  // what ran, for failure messages
  int exit_code = -1;
  std::vector<Event> output;  // the output log's events (empty when it was not written)
};

// Runs bin_dir()/<program> <args> reading the log `in` (file://in?speed=0) and writing the log
// `out` (file://out?mode=w, replaced), then reads `out`. `args` may redirect stderr ("2>file").
LogRun run_from_log(const std::string& program, const std::string& args, const std::string& in,
                    const std::string& out);

}  // namespace nudge::test
