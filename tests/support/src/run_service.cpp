#include "nudge/test/run_service.hpp"

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <mutex>
#include <set>
#include <system_error>

namespace nudge::test {

std::string bin_dir() { return NUDGE_BIN_DIR; }

namespace {

// The paths temp_path handed out, removed at exit when every test passed (the registry is made on
// the first call, inside RUN_ALL_TESTS, so it is destroyed before gtest's UnitTest).
class TempPaths {
 public:
  void add(const std::string& path) {
    std::lock_guard<std::mutex> lock(mutex_);
    paths_.insert(path);
  }
  ~TempPaths() {
    if (std::getenv("NUDGE_KEEP_TEST_RUNS") || !testing::UnitTest::GetInstance()->Passed()) return;
    std::error_code ignored;
    for (const std::string& path : paths_) std::filesystem::remove_all(path, ignored);
  }

 private:
  std::mutex mutex_;
  std::set<std::string> paths_;
};

TempPaths& temp_paths() {
  static TempPaths paths;
  return paths;
}

}  // namespace

std::string temp_path(const std::string& name) {
  const std::string path = testing::TempDir() + "/" + std::to_string(::getpid()) + "_" + name;
  temp_paths().add(path);
  return path;
}

int run_command(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

CommandOutput run_capturing(const std::string& command) {
  static std::atomic<int> counter{0};
  const std::string err_path = temp_path("stderr_" + std::to_string(counter++) + ".txt");
  CommandOutput result;
  FILE* pipe = ::popen((command + " 2>" + err_path).c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run " + command);
  std::array<char, 4096> buf{};
  for (size_t n; (n = std::fread(buf.data(), 1, buf.size(), pipe)) > 0;) result.out.append(buf.data(), n);
  const int status = ::pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream err(err_path);
  result.err.assign(std::istreambuf_iterator<char>(err), std::istreambuf_iterator<char>());
  std::remove(err_path.c_str());
  return result;
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
