#include "nudge/launcher/process_group.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include "nudge/log.hpp"
#include "nudge/timing.hpp"

namespace nudge::launcher {

namespace {

int exit_code_of(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

// In the child, between fork and exec: only async-signal-safe calls.
[[noreturn]] void exec_child(const std::vector<std::string>& argv, int log_fd) {
  setpgid(0, 0);  // its own group: a Ctrl-C at the terminal reaches the launcher, which stops it
  dup2(log_fd, STDOUT_FILENO);
  dup2(log_fd, STDERR_FILENO);
  int devnull = open("/dev/null", O_RDONLY);
  if (devnull >= 0) dup2(devnull, STDIN_FILENO);
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  execvp(args[0], args.data());
  const char* msg = "nudge-launch: cannot run the program: ";
  (void)!write(STDERR_FILENO, msg, strlen(msg));
  (void)!write(STDERR_FILENO, args[0], strlen(args[0]));
  (void)!write(STDERR_FILENO, "\n", 1);
  _exit(127);
}

}  // namespace

std::string to_string(ProcessState state) {
  switch (state) {
    case ProcessState::kRunning: return "running";
    case ProcessState::kBackoff: return "backoff";
    case ProcessState::kExited: return "exited";
    case ProcessState::kStopping: return "stopping";
    case ProcessState::kStopped: return "stopped";
  }
  return "?";
}

ProcessGroup::ProcessGroup(LaunchConfig config) : config_(std::move(config)) {
  std::error_code error;
  std::filesystem::create_directories(config_.log_dir, error);
  if (error) throw std::runtime_error("cannot create the log folder " + config_.log_dir + ": " + error.message());
  for (const ProcessSpec& spec : config_.processes) {
    Child child;
    child.spec = spec;
    child.log = (std::filesystem::path(config_.log_dir) / (spec.name + ".log")).string();
    children_.push_back(std::move(child));
  }
}

ProcessGroup::~ProcessGroup() { stop(); }

void ProcessGroup::launch(Child& child, int64_t now_utime) {
  const std::vector<std::string> argv = command_line(child.spec, config_.lcm_url);
  const int log_fd = open(child.log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) {
    log::error() << child.spec.name << ": cannot open its log " << child.log << ": " << strerror(errno);
    ended(child, 127, now_utime);
    return;
  }
  const pid_t pid = fork();
  if (pid == 0) exec_child(argv, log_fd);
  close(log_fd);
  if (pid < 0) {
    log::error() << child.spec.name << ": fork failed: " << strerror(errno);
    ended(child, 127, now_utime);
    return;
  }
  setpgid(pid, pid);  // also from the parent: no race with a stop() right after the fork
  child.pid = pid;
  child.state = ProcessState::kRunning;
  child.started_utime = now_utime;
  log::info() << child.spec.name << " started (pid " << pid << "), log " << child.log;
}

void ProcessGroup::start(int64_t now_utime) {
  for (Child& child : children_) launch(child, now_utime);
}

void ProcessGroup::ended(Child& child, int exit_code, int64_t now_utime) {
  child.pid = 0;
  child.last_exit_code = exit_code;
  const bool failed = exit_code != 0;
  const bool restart = child.spec.restart == RestartPolicy::kAlways ||
                       (child.spec.restart == RestartPolicy::kOnFailure && failed);
  if (!restart) {
    child.state = ProcessState::kExited;
    log::info() << child.spec.name << " ended (exit code " << exit_code << ")";
    return;
  }
  const bool quick = now_utime - child.started_utime < static_cast<int64_t>(config_.backoff.stable_s * 1e6);
  child.quick_failures = quick ? child.quick_failures + 1 : 1;
  const double delay = restart_delay_s(child.quick_failures, config_.backoff);
  child.state = ProcessState::kBackoff;
  child.restart_at_utime = now_utime + static_cast<int64_t>(delay * 1e6);
  log::warn() << child.spec.name << " ended (exit code " << exit_code << "); restarting in " << delay << " s";
}

bool ProcessGroup::poll(int64_t now_utime) {
  bool changed = false;
  for (Child& child : children_) {
    if (child.pid > 0) {
      int status = 0;
      if (waitpid(child.pid, &status, WNOHANG) == child.pid) {
        ended(child, exit_code_of(status), now_utime);
        changed = true;
      }
    }
    if (child.state == ProcessState::kBackoff && now_utime >= child.restart_at_utime) {
      ++child.restarts;
      launch(child, now_utime);
      changed = true;
    }
  }
  return changed;
}

int ProcessGroup::stop() {
  for (Child& child : children_) {
    if (child.pid > 0) {
      kill(-child.pid, SIGINT);  // its group: a wrapper script's children too
      child.state = ProcessState::kStopping;
    } else {
      child.state = child.state == ProcessState::kExited ? ProcessState::kExited : ProcessState::kStopped;
    }
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(config_.stop_timeout_s);
  int killed = 0;
  for (;;) {
    bool running = false;
    for (Child& child : children_) {
      if (child.pid <= 0) continue;
      int status = 0;
      if (waitpid(child.pid, &status, WNOHANG) == child.pid) {
        child.last_exit_code = exit_code_of(status);
        child.pid = 0;
        child.state = ProcessState::kStopped;
      } else {
        running = true;
      }
    }
    if (!running) return killed;
    if (std::chrono::steady_clock::now() >= deadline) {
      for (Child& child : children_) {
        if (child.pid <= 0) continue;
        log::warn() << child.spec.name << " did not stop within " << config_.stop_timeout_s << " s: SIGKILL";
        kill(-child.pid, SIGKILL);
        waitpid(child.pid, nullptr, 0);
        child.pid = 0;
        child.state = ProcessState::kStopped;
        child.last_exit_code = 128 + SIGKILL;
        ++killed;
      }
      return killed;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

std::vector<ProcessInfo> ProcessGroup::status(int64_t now_utime) const {
  std::vector<ProcessInfo> out;
  for (const Child& child : children_) {
    ProcessInfo info;
    info.name = child.spec.name;
    info.log = child.log;
    info.pid = child.pid;
    info.state = child.state;
    info.restarts = child.restarts;
    info.last_exit_code = child.last_exit_code;
    if (child.state == ProcessState::kRunning) info.uptime_s = (now_utime - child.started_utime) * 1e-6;
    if (child.state == ProcessState::kBackoff) info.restart_in_s = (child.restart_at_utime - now_utime) * 1e-6;
    out.push_back(info);
  }
  return out;
}

}  // namespace nudge::launcher
