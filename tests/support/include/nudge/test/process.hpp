#pragma once
// A child process for integration tests: started with posix_spawn (standard output to /dev/null,
// standard error to a log file), stopped with SIGINT and, if it does not end within 5 s, SIGKILL
// when the object goes.
#include <sys/types.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace nudge::test {

class Process {
 public:
  // argv[0] is the program's path (no PATH search). started() is false when it could not start.
  Process(const std::vector<std::string>& argv, const std::string& log);
  Process(const Process&) = delete;
  Process& operator=(const Process&) = delete;
  ~Process() { stop(); }

  bool started() const { return pid_ > 0; }

  // Waits for the process to end by itself; its exit code, or -1 if it is still running after
  // `seconds` (or was killed by a signal).
  int wait_exit(double seconds);

  // Sends `signal_number` to the process, if it is running.
  void signal(int signal_number);

  // SIGINT, then SIGKILL after 5 s; waits for the process to end.
  void stop();

 private:
  pid_t pid_ = -1;
};

// The whole of a text file (a process's log, a summary); "" when it cannot be read.
inline std::string read_file(const std::string& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace nudge::test
