#pragma once
// The bus vocabulary: every LCM channel name the services use, in one place, and the one rule
// that names a camera's derived channels (CAMERA_LEFT -> SYMMETRY_LEFT, TRACK_LEFT, ...).
// Header only and free of LCM, so that tests and experiments that speak raw LCM can use it too.
// docs/architecture.md lists who publishes and who reads each channel.
#include <stdexcept>
#include <string>

namespace nudge::bus::channel {

// Images (image_t): a stereo pair, or one mono camera. CAMERA is also the prefix that derived()
// replaces.
inline constexpr const char* CAMERA = "CAMERA";
inline constexpr const char* CAMERA_LEFT = "CAMERA_LEFT";
inline constexpr const char* CAMERA_RIGHT = "CAMERA_RIGHT";
inline constexpr const char* CAMERA_SNAPSHOT_REQUEST = "CAMERA_SNAPSHOT_REQUEST";  // snapshot_request_t
inline constexpr const char* SNAPSHOT_LEFT = "SNAPSHOT_LEFT";                      // image_t, full size
inline constexpr const char* SNAPSHOT_RIGHT = "SNAPSHOT_RIGHT";

// Per-camera results: each kind is both the mono channel's name and the prefix of the stereo
// channels derived from the camera channels.
inline constexpr const char* SYMMETRY = "SYMMETRY";  // symmetry_lines_t
inline constexpr const char* SYMMETRY_LEFT = "SYMMETRY_LEFT";
inline constexpr const char* SYMMETRY_RIGHT = "SYMMETRY_RIGHT";
inline constexpr const char* CONTOURS = "CONTOURS";  // contours_t
inline constexpr const char* CONTOURS_LEFT = "CONTOURS_LEFT";
inline constexpr const char* CONTOURS_RIGHT = "CONTOURS_RIGHT";
inline constexpr const char* TRACK = "TRACK";  // track_t
inline constexpr const char* TRACK_LEFT = "TRACK_LEFT";
inline constexpr const char* TRACK_RIGHT = "TRACK_RIGHT";
inline constexpr const char* TRACKER_COMMAND = "TRACKER_COMMAND";  // tracker_command_t

// Stereo geometry.
inline constexpr const char* AXES = "AXES";                              // axes_t
inline constexpr const char* CANDIDATES = "CANDIDATES";                  // candidates_t
inline constexpr const char* CANDIDATES_REQUEST = "CANDIDATES_REQUEST";  // candidates_request_t

// The arm.
inline constexpr const char* ARM_COMMAND = "ARM_COMMAND";  // arm_command_t
inline constexpr const char* ARM_STATE = "ARM_STATE";      // arm_state_t

// The simulated world.
inline constexpr const char* SIM_STATE = "SIM_STATE";                  // sim_state_t
inline constexpr const char* SIM_TRUTH = "SIM_TRUTH";                  // sim_truth_t
inline constexpr const char* SIM_TRUTH_REQUEST = "SIM_TRUTH_REQUEST";  // sim_truth_request_t

// Every service.
inline constexpr const char* HEARTBEAT = "HEARTBEAT";  // heartbeat_t

// The supervisor's state machine and what it segments.
inline constexpr const char* SUPERVISOR_STATE = "SUPERVISOR_STATE";  // supervisor_state_t
inline constexpr const char* SEGMENTATION = "SEGMENTATION";          // segmentation_t

// Learning and recognition (the learner service).
inline constexpr const char* LEARN_VIEW = "LEARN_VIEW";                // learn_view_t
inline constexpr const char* LEARN_COMMIT = "LEARN_COMMIT";            // learn_commit_t
inline constexpr const char* LEARNED = "LEARNED";                      // learn_result_t
inline constexpr const char* RECOGNIZE_REQUEST = "RECOGNIZE_REQUEST";  // recognize_request_t
inline constexpr const char* RECOGNITION = "RECOGNITION";              // recognition_t

// A replayed log under the operator's control (nudge-replay; nudge-viewer sends the commands).
inline constexpr const char* REPLAY_COMMAND = "REPLAY_COMMAND";  // replay_command_t
inline constexpr const char* REPLAY_STATUS = "REPLAY_STATUS";    // replay_status_t

// The set of processes nudge-launch runs.
inline constexpr const char* PROCESS_STATUS = "PROCESS_STATUS";  // process_status_t

// The channel of kind `kind` (SYMMETRY, CONTOURS, TRACK) that results from a camera channel:
// CAMERA_LEFT -> SYMMETRY_LEFT, CAMERA -> SYMMETRY; a channel not named CAMERA... keeps its
// name behind the kind, so that two inputs never share an output: LEFT_EYE -> SYMMETRY_LEFT_EYE.
inline std::string derived(const std::string& camera_channel, const std::string& kind) {
  const std::string prefix = CAMERA;
  if (camera_channel.rfind(prefix, 0) == 0) return kind + camera_channel.substr(prefix.size());
  return kind + "_" + camera_channel;
}

// The camera channel a channel of kind `kind` was derived from: SYMMETRY_LEFT -> CAMERA_LEFT,
// SYMMETRY -> CAMERA (the inverse of derived() for camera channels named CAMERA...). Throws
// std::invalid_argument naming a channel that is not of that kind.
inline std::string camera_of(const std::string& derived_channel, const std::string& kind) {
  if (derived_channel.rfind(kind, 0) != 0)
    throw std::invalid_argument("channel " + derived_channel + " is not a " + kind + "* channel");
  return CAMERA + derived_channel.substr(kind.size());
}

}  // namespace nudge::bus::channel
