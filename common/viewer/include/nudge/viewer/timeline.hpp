#pragma once
// The supervisor's states as a timeline: one entry per transition. The supervisor repeats its
// state once a second; a repeat (same state, attempt and reason) only refreshes the counts.
#include <cstdint>
#include <deque>
#include <string>

namespace nudge::viewer {

struct StateEntry {
  int64_t utime = 0;  // the supervisor's task clock
  std::string run_id, state;
  int attempt = 0;
  std::string reason;
  int segmented = 0, failed_attempts = 0;
  double target[3] = {0, 0, 0};
  bool has_target = false;
};

class StateTimeline {
 public:
  explicit StateTimeline(size_t max_entries = 500) : max_entries_(max_entries) {}
  // Returns whether the entry was a transition (appended).
  bool observe(const StateEntry& entry);
  const std::deque<StateEntry>& entries() const { return entries_; }

 private:
  size_t max_entries_;
  std::deque<StateEntry> entries_;
};

}  // namespace nudge::viewer
