#pragma once
// launcher::ProcessInfo -> process_status_t (nudge_bus_launcher): the PROCESS_STATUS message
// nudge-launch publishes. nudge-viewer reads it back with bus::process_rows_of (viewer_convert.hpp).
#include <cstdint>
#include <string>
#include <vector>

#include "nudge/launcher/process_group.hpp"
#include "nudge/process_status_t.hpp"

namespace nudge::bus {

// process_info_t's STATE_* code of a launcher state.
int8_t to_message(launcher::ProcessState state);

// The status of a launch file's processes (`config_path`) at `utime`.
process_status_t to_message(const std::vector<launcher::ProcessInfo>& processes, int64_t utime,
                            const std::string& config_path);

}  // namespace nudge::bus
