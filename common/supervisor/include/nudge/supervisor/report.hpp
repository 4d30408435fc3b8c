#pragma once
// What a run leaves on disk: per attempt the stills, the segmentation (mask, cut-out, fig. 6.7's
// stages) and the fig. 6.6 picture of the planned push; per run a JSON summary. Every file is
// written atomically (temporary file + rename): a crash leaves no half-written file.
#include <opencv2/core.hpp>

#include <optional>
#include <string>

#include "nudge/supervisor/supervisor.hpp"

namespace nudge::supervisor {

// Fig. 6.6: the table from above (1 px per mm, the arm base at the centre of the ring): the
// workspace ring white, the right camera red, every candidate of the survey as a blue circle with
// its centroid, those passed over crossed, the target ringed and the planned push a green arrow
// from P1 to P2.
cv::Mat draw_workspace(const Attempt& attempt, const ArmSetup& arm, const Eigen::Vector3d& right_camera);

// Writes `directory`/attempt_NN/{before,after,mask,cutout,workspace}.png, stages/ and attempt.json;
// when learning, also {before,after,mask}_left.png (views/ is written by save_view).
// Returns the attempt's folder. Throws std::runtime_error naming a file that cannot be written.
std::string save_attempt(const std::string& directory, const Attempt& attempt, const ArmSetup& arm,
                         const Eigen::Vector3d& right_camera);

// A training view as `directory`/attempt_NN/views/view_II.png (written as it is taken: a learner
// that never answers leaves the views on disk). Returns the file's path; throws naming it.
std::string save_view(const std::string& directory, int attempt_number, const LearnView& view);

// One attempt as a JSON object (outcome, reason, target, rest, motion, lines, mask pixels, times).
std::string attempt_json(const Attempt& attempt);
// A line attempt_json wrote under `key` ("line_before", "line_after", "line_before_left", ...): its
// R and theta (votes too); nothing when the key is absent or null. For the programs that replay an
// attempt's stills (nudge-exp-nudge-segmentation, grasp_plan_bench --attempt).
std::optional<symmetry::Line> recorded_line(const std::string& attempt_json, const std::string& key);
// The run's summary: run id, counts, outcomes, the attempts, the end reason.
std::string summary_json(const std::string& run_id, int64_t first_command_seq, const Summary& summary, const std::vector<std::string>& attempts_json);

}  // namespace nudge::supervisor
