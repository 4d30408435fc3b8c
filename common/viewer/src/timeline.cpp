#include "nudge/viewer/timeline.hpp"

namespace nudge::viewer {

bool StateTimeline::observe(const StateEntry& entry) {
  if (!entries_.empty()) {
    StateEntry& last = entries_.back();
    if (last.run_id == entry.run_id && last.state == entry.state && last.attempt == entry.attempt &&
        last.reason == entry.reason) {
      last.segmented = entry.segmented;
      last.failed_attempts = entry.failed_attempts;
      return false;
    }
  }
  entries_.push_back(entry);
  while (entries_.size() > max_entries_) entries_.pop_front();
  return true;
}

}  // namespace nudge::viewer
