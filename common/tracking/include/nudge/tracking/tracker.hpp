#pragma once
// Real-time symmetry tracker (Li 2008, ch. 5, fig. 5.1): block motion masks the edges, the fast
// symmetry detector measures lines within the Kalman prediction's angle limits, a chi^2
// validation gate associates the nearest line, and an automatic start bootstraps the filter.
//
//   SymmetryTracker tracker;
//   for (each frame) { TrackState s = tracker.feed(grey, utime); if (s.status == TrackStatus::Tracking) ... }
//
// Status (numbers equal track_t's STATUS_* constants):
//   Idle          waiting for the object to start moving (no estimate)
//   Initialising  motion started; collecting the three frames of the automatic start
//   Tracking      the filter has an estimate; `measurement_used` says whether this frame updated it;
//                 `holding` = the object stood still this frame (line held, nothing detected)
//   Lost          the track ended; `reason` says why (no gated line for N frames, the line left the
//                 image, or bad input: a size change, a frame out of order, a time jump, or a
//                 restart request). The tracker re-arms itself: after a loss of the line (or a
//                 failed automatic start), a new jump in motion starts a new initialisation, and
//                 so does any motion once StartParams::rearm_frames have passed (motion that never
//                 stopped, as in a hand-held video, would otherwise never count as a jump); after
//                 bad input or a restart (which forget the past frames), any motion does.
//                 TrackState::tracks_started counts the tracks begun: a new value is a re-acquisition.
#include <opencv2/core.hpp>

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "nudge/symmetry/detector.hpp"
#include "nudge/tracking/block_motion.hpp"
#include "nudge/tracking/kalman.hpp"
#include "nudge/tracking/refine.hpp"

namespace nudge::tracking {

enum class TrackStatus : int8_t { Idle = 0, Initialising = 1, Tracking = 2, Lost = 3 };
const char* to_string(TrackStatus status);

struct StartParams {
  // A "sharp jump" in the number of moving blocks: at least min_blocks, and at least jump_factor
  // times the recent (exponentially averaged) count of the idle frames before it.
  int min_blocks = 6;
  double jump_factor = 3.0;
  double baseline_smoothing = 0.2;  // weight of the newest frame in the idle baseline
  // The 3-frame association window slides on while no association passes the gate; after this
  // many frames without a consistent start the tracker gives up and waits for new motion.
  int max_frames = 15;
  // Not in the thesis: accumulated gate errors closer than this are a tie, broken in favour of the
  // stronger lines. An object moving by about the spacing of its inner symmetric contours per
  // frame (shading bands, a label) gives a chain of secondary lines exactly as consistent as the
  // true one; the thesis' rule alone then picks either.
  double tie_margin = 1.0;
  // Not in the thesis: after a lost track or a failed automatic start, any motion of at least
  // min_blocks starts a new initialisation once this many frames have passed, jump or not (the
  // thesis' jump rule alone never re-acquires an object whose motion goes on through the loss).
  // 0 = only a new jump re-arms.
  int rearm_frames = 5;
  // Not in the thesis: for this many frames after a track is lost, the automatic start prefers
  // lines near where the object was: in each frame of the start window, the lines inside the lost
  // track's validation gate (its line held where it was last seen, its covariance growing with the
  // frames since) are the only candidates when there are any. Without it the strongest moving line
  // wins, and a distractor crossing the resting object's place is taken for it. 0 = off.
  int reacquire_frames = 25;
};

struct TrackerParams {
  BlockMotionParams motion;
  KalmanParams kalman;
  RefineParams refine;
  StartParams start;
  symmetry::EdgeParams edges{1.0, 30.0, 90.0, false};  // thesis: blur, Canny 30/90
  // Detector for 640x480 indoor frames (thesis: Dmin 25, Dmax 250; Nlines = 3 for the automatic
  // start's 27 associations). theta_min/max_deg limit the search only before tracking starts;
  // while tracking the limits come from the prediction.
  symmetry::Params detector = default_detector();
  double gate_sigmas = 3.0;          // angle limits = predicted theta +- gate_sigmas * sigma (thesis: 3)
  double min_half_width_deg = 3.0;   // never search a narrower angle range than +- this
  // Not in the thesis: when less than this fraction of the track's blocks (its symmetry-refined
  // motion mask of the last frame with motion) moves now, the object has stopped: the filter holds
  // its line (LineKalman::hold: no coasting on the old velocity) and offers no measurement (any
  // line now comes from something else that moves). Such frames count as predict-only frames.
  // 0 = always predict (the thesis).
  double still_fraction = 0.2;
  // Not in the thesis: association by gate error AND support. Among the lines inside the gate the
  // one with the least  gate error + support_weight * 2 ln(strongest votes / its votes)  updates
  // the filter (0 = the thesis' nearest line). A weaker line next to the prediction then no longer
  // beats the object's own, much stronger line a little further off (a secondary line that the
  // estimate drifted onto is otherwise kept for ever, as it is always the nearest).
  double support_weight = 4.0;
  int max_missed_frames = 10;        // consecutive predict-only frames before the track is Lost
  // Not in the thesis: a held object whose own symmetry line is still there (the edges in its
  // blocks, moving or not, give a line inside the gate with at least half the support of the last
  // line used) is resting, not missing: such frames do not count towards max_missed_frames, and
  // the track survives a rest of up to this many frames (stop-and-go motion: pauses of 8-15 frames
  // ended tracks at 10). An object that vanished or was covered leaves no such line: its held
  // frames are missed ones. 0 = every held frame is a missed one (before issue 15's follow-up).
  int max_rest_frames = 125;         // 5 s at 25 Hz
  int64_t max_frame_gap_us = 500000; // a longer gap between frames is a time jump: re-initialise

  static symmetry::Params default_detector() {
    symmetry::Params p;
    p.dmin = 25;
    p.dmax = 250;
    p.num_lines = 3;
    // Thesis sec. 3.2.3, straight-line rejection: skip rows of Rot with more edge pixels than
    // this. Without it the long straight sides of a moving bottle outvote its symmetry (pairs
    // along one straight edge vote for the edge itself). Motion-masked rows across an object hold
    // a few dozen pixels at most; a straight edge seen end-on holds its whole length. (The
    // stronger once_per_row rule also works but gives a shaded object's inner contours as many
    // votes as its outline, so secondary lines tie with the axis.)
    p.max_row_pixels = 50;
    return p;
  }
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const TrackerParams& params);

struct TrackTiming {
  double motion_ms = 0, edges_ms = 0, detect_ms = 0, kalman_ms = 0, refine_ms = 0;
  double total_ms() const { return motion_ms + edges_ms + detect_ms + kalman_ms + refine_ms; }
};

struct TrackState {
  TrackStatus status = TrackStatus::Idle;
  std::string reason;              // why Idle / Initialising / Lost; empty while tracking normally
  int64_t utime = 0;
  int64_t frame_index = 0;         // frames fed since construction
  int width = 0, height = 0;
  bool has_estimate = false;       // true while Tracking (and on the frame a track is Lost)
  symmetry::Line line;             // posterior estimate: r px, theta rad in (-pi/2, pi/2], end points
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // of (R px, theta rad)
  bool has_box = false;
  std::array<cv::Point2d, 4> box{};  // rotated bounding box, two sides parallel to the line
  int block_size = 8;
  cv::Mat blocks;                  // CV_8U 0/1 per block: symmetry-refined while tracking, else IRES
  int moving_blocks = 0;           // after the median filter (the automatic start's signal)
  int lines_detected = 0;          // measurements offered this frame
  std::vector<LineMeasurement> measurements;  // those lines (R px, theta deg), strongest first
  bool measurement_used = false;   // a line passed the gate and updated the filter
  double gate_error = 0;           // normalised innovation squared of the line used
  int missed_frames = 0;           // consecutive predict-only frames
  AngleLimits limits;              // detection angle limits used for this frame, degrees
  double object_motion = -1;       // fraction of the track's blocks moving this frame (-1: not tracking)
  bool holding = false;            // the object stood still: line held, no detection this frame
  int resting_frames = 0;          // consecutive held frames in which the object's own line was still there
  int tracks_started = 0;          // tracks begun since construction (automatic starts and start_at)
  TrackTiming ms;
};

class SymmetryTracker {
 public:
  // Throws std::invalid_argument for bad parameters.
  explicit SymmetryTracker(TrackerParams params = {});

  // One video frame (8-bit grey, BGR or BGRA) with its capture time. Never throws for bad input:
  // an empty or unusable frame is skipped with a reason; a size change, a frame out of order or a
  // time jump ends the current track (Lost, with the reason) and the tracker starts over.
  TrackState feed(const cv::Mat& frame, int64_t utime);
  // Ends any track and waits for new motion (the service's restart request).
  void restart(const std::string& reason = "restart requested");
  // Starts a track at a line known from elsewhere (R px, theta rad in this camera's frames), at
  // rest, instead of waiting for the automatic start: the supervisor knows where the object it
  // nudges stands (thesis sec. 6.3.2: motion at the target starts one tracker per camera). The
  // next frame predicts from it and measures as in any track.
  void start_at(const symmetry::Line& line);

  const TrackerParams& params() const { return params_; }
  TrackStatus status() const { return status_; }

 private:
  bool accept_frame(const cv::Mat& frame, int64_t utime, cv::Mat* grey, TrackState* state);
  void reset(TrackStatus status, const std::string& reason);
  void process(const cv::Mat& grey, TrackState* state);
  std::vector<LineMeasurement> detect_lines(const cv::Mat& grey, const BlockMotion& motion,
                                            const AngleLimits& limits, TrackState* state);
  void watch_for_start(const BlockMotion& motion);
  void initialise(const cv::Mat& grey, const BlockMotion& motion, TrackState* state);
  void track(const cv::Mat& grey, const BlockMotion& motion, TrackState* state);
  void hold(const cv::Mat& grey, const BlockMotion& motion, TrackState* state);
  bool measure_in_place(const cv::Mat& grey, const BlockMotion& motion, TrackState* state);
  void end_track(const std::string& reason, TrackState* state);
  void age_lost_track();
  void describe_estimate(const BlockMotion& motion, TrackState* state);

  TrackerParams params_;
  TrackStatus status_ = TrackStatus::Idle;
  std::string reason_;
  cv::Mat previous_;
  int64_t previous_utime_ = 0;
  int64_t frames_ = 0;
  double idle_baseline_ = 0;
  std::vector<std::vector<LineMeasurement>> start_window_;  // line sets of the last <= 3 frames
  int start_frames_ = 0;
  LineKalman kalman_;
  int missed_ = 0;
  int frames_since_loss_ = -1;  // counting towards StartParams::rearm_frames; -1 = not after a loss
  int tracks_started_ = 0;
  LineKalman last_measured_track_;  // the filter after the track's last update
  LineKalman lost_track_;        // the last track's filter, held where it was last measured
  int frames_since_lost_track_ = -1;  // -1: no recent lost track to re-acquire near
  cv::Mat object_blocks_;  // the track's symmetry-refined blocks of its last frame with motion
  double last_votes_ = 0;  // support of the line of the track's last update
  int resting_ = 0;        // consecutive held frames with the object looking as last measured
};

// The best of all associations of one line per frame across three frames (27 for Nlines = 3):
// the filter is started on the first line and updated with the others; the association with the
// least accumulated gate error wins if every step passed the gate. Associations within tie_margin
// of each other count as equally consistent and the one using the stronger lines wins (lines are
// given strongest first). Returns false when no association passed the gate.
// The line that updates the filter: among the lines inside the validation gate, the one with the
// least  gate error + support_weight * 2 ln(v_max / v), where v is its votes and v_max those of the
// strongest line inside the gate (support_weight 0, or unknown votes: the thesis' nearest line).
// Returns its index, or -1 when no line is inside the gate; *gate_error gets its gate error.
int associate(const LineKalman& filter, const std::vector<LineMeasurement>& lines, double support_weight,
              double* gate_error = nullptr);

bool best_start(const std::vector<std::vector<LineMeasurement>>& frames, const KalmanParams& params,
                LineKalman* filter, double* total_gate_error, double tie_margin = 0.0);

// Re-acquiring near a lost track: each frame's lines inside `lost`'s validation gate, or all of
// that frame's lines when none is (the start window the tracker gives best_start within
// StartParams::reacquire_frames of a loss).
std::vector<std::vector<LineMeasurement>> lines_near(const LineKalman& lost,
                                                     const std::vector<std::vector<LineMeasurement>>& frames);

}  // namespace nudge::tracking
