#pragma once
// supervisor_state_t -> viewer::StateEntry (nudge_bus_viewer), shared by nudge-viewer (live) and
// nudge-report (from a run's log), so that both show the same timeline.
#include <string>
#include <vector>

#include "nudge/supervisor_state_t.hpp"
#include "nudge/viewer/timeline.hpp"

namespace nudge::bus {

viewer::StateEntry state_entry_of(const supervisor_state_t& msg);

// The supervisor's transitions in an LCM log (its 1 Hz repeats folded as viewer::StateTimeline
// does); malformed SUPERVISOR_STATE events are skipped. Throws std::runtime_error naming the log
// when it cannot be read.
std::vector<viewer::StateEntry> supervisor_states_in_log(const std::string& log_path);

}  // namespace nudge::bus
