#pragma once
// Helpers for the programs that replay recorded loop runs (experiments/nudge_segmentation.sh's
// RUNS_DIR/<scene>/<scene>/<scene>.lcmlog) through a service: the runs' logs, a channel's messages,
// the simulator's state at a moment, and a service started as a shell command.
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "nudge/sim_state_t.hpp"

namespace nudge::experiments {

// Every run log under each RUNS_DIR, named "<k>:<scene>" (k: the RUNS_DIR's place, from 1), sorted
// within each set. Throws when there is none at all.
std::vector<std::pair<std::string, std::filesystem::path>> run_logs(const std::vector<std::string>& run_sets);

// Every message of `channel` in a log, in log order (undecodable ones skipped).
template <typename Message>
std::vector<Message> read_channel(const std::filesystem::path& log_path, const std::string& channel) {
  std::vector<Message> messages;
  lcm::LogFile log(log_path.string(), "r");
  if (!log.good()) throw std::runtime_error("cannot read " + log_path.string());
  for (const lcm::LogEvent* e = log.readNextEvent(); e; e = log.readNextEvent()) {
    if (e->channel != channel) continue;
    Message m;
    if (m.decode(e->data, 0, e->datalen) >= 0) messages.push_back(std::move(m));
  }
  return messages;
}

// The latest message at or before `utime` (messages in log order, utime rising); null before the
// first.
template <typename Message>
const Message* latest_at(const std::vector<Message>& messages, int64_t utime) {
  const Message* found = nullptr;
  for (const auto& m : messages) {
    if (m.utime > utime) break;
    found = &m;
  }
  return found;
}

// The simulator's state at `utime` (latest_at).
inline const sim_state_t* state_at(const std::vector<sim_state_t>& states, int64_t utime) { return latest_at(states, utime); }

// The directory of the running program (where the services' binaries are built beside it).
std::filesystem::path own_directory();
// A comma-separated list of positive numbers given to `flag`; throws naming the flag and the item.
std::vector<double> parse_list(const std::string& text, const std::string& flag);
// `s` as one word for /bin/sh.
std::string shell_quote(const std::string& s);

// The run's camera frames (CAMERA_LEFT/RIGHT in `log`) through nudge-symmetry (built beside this
// program) with the run's own flags (its services/launch.json beside the log) and then `extra`
// (later flags win), its lines written to the log `out`. Throws naming the run when it fails.
void replay_symmetry(const std::filesystem::path& log, const std::string& extra, const std::filesystem::path& out);

}  // namespace nudge::experiments
