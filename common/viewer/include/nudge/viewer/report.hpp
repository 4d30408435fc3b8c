#pragma once
// A run's report (out/runs/<run>/report.html): one HTML file that opens in a browser with no
// server (images by relative path). It shows the run's figures from summary.json (attempts,
// outcomes, times per attempt), the timeline of the supervisor's states, and per attempt its
// stills, mask and cut-out, the fig. 6.6 picture, the fig. 6.7 stages, the tracking plot (θ of
// each tracker over time, from attempt.json's track_trace) and any other pictures the attempt's
// folder holds (learned views, recognition matches). nudge-report is its shell.
#include <string>
#include <vector>

#include "nudge/viewer/timeline.hpp"

namespace nudge::viewer {

// One attempt's mask scored against the simulator's true masks (nudge-report --scene).
struct SimulationScore {
  int attempt = 0;
  int object = -1;          // the scene's index of the object the mask covers most; -1: none
  std::string object_name;  // its name in the scene file
  double iou = 0;           // the mask's intersection over union with that object's true mask
};

// Reads RUN_DIR (summary.json, attempt_NN/) and renders the report; `states` are the supervisor's
// transitions (from the run's log); `scores`, in simulation, give the IoU per object (a table of
// the scene's objects with the best IoU each got) and per attempt. Throws std::runtime_error
// naming the file when summary.json is missing or not JSON.
std::string render_run_report(const std::string& run_dir, const std::vector<StateEntry>& states,
                              const std::vector<SimulationScore>& scores = {});

}  // namespace nudge::viewer
