#pragma once
// supervisor_state_t -> viewer::StateEntry (nudge_bus_viewer), shared by nudge-viewer (live) and
// nudge-report (from a run's log), so that both show the same timeline; process_status_t (what
// nudge-launch publishes, process_status_convert.hpp) -> the page's process rows.
#include <string>
#include <vector>

#include "nudge/process_status_t.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/viewer/timeline.hpp"
#include "nudge/viewer/view_model.hpp"

namespace nudge::bus {

viewer::StateEntry state_entry_of(const supervisor_state_t& msg);

// The supervisor's transitions in an LCM log (its 1 Hz repeats folded as viewer::StateTimeline
// does); malformed SUPERVISOR_STATE events are skipped. Throws std::runtime_error naming the log
// when it cannot be read.
std::vector<viewer::StateEntry> supervisor_states_in_log(const std::string& log_path);

// The page's rows of nudge-launch's processes; a state as the page names it ("restarting" for
// STATE_BACKOFF; "state N" for a code this build does not know).
std::vector<viewer::ProcessRow> process_rows_of(const process_status_t& msg);

}  // namespace nudge::bus
