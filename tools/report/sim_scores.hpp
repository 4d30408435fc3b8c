#pragma once
// In simulation: every segmentation of a run scored against the simulator's truth, for the
// report's IoU per object. Built only with the simulator (NUDGE_REPORT_SIM).
#include <string>
#include <vector>

#include "nudge/viewer/report.hpp"

namespace nudge::report {

// For each SEGMENTATION in the run's log, the scene (the file the run's world loaded) is posed as
// the last SIM_STATE before it and rendered from the right camera's still: the object the mask
// covers most and the IoU with its true mask. Throws std::runtime_error naming the log or scene
// file when either cannot be read, or a mask whose size is not the still's.
std::vector<viewer::SimulationScore> simulation_scores(const std::string& log_path, const std::string& scene_file);

}  // namespace nudge::report
