#include "nudge/tracking/tracker.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "nudge/timing.hpp"

namespace nudge::tracking {

namespace {
constexpr double kDegPerRad = 180.0 / M_PI;
constexpr const char* kWaitingForFirstFrame = "waiting for the first frame";

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

std::string size_text(const cv::Size& s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

bool track_active(TrackStatus s) { return s == TrackStatus::Tracking || s == TrackStatus::Initialising; }

// (R px, theta deg) covariance -> (R px, theta rad).
Eigen::Matrix2d to_radians(const Eigen::Matrix2d& cov_deg) {
  const Eigen::Vector2d scale(1.0, 1.0 / kDegPerRad);
  return scale.asDiagonal() * cov_deg * scale.asDiagonal();
}
// Canny edges of a grey image (thesis: aperture 3). The blur goes into a new image:
// symmetry::detect_edges blurs a single-channel input in place (in the caller's buffer), which
// would corrupt the frame kept as the next I0 of the block motion detector.
cv::Mat edge_pixels(const cv::Mat& grey, const symmetry::EdgeParams& params) {
  cv::Mat source;
  if (params.blur_sigma > 0) {
    cv::GaussianBlur(grey, source, cv::Size(0, 0), params.blur_sigma);
  } else {
    source = grey;
  }
  cv::Mat edges;
  if (params.auto_canny || source.rows < 3 || source.cols < 3) {
    symmetry::EdgeParams unblurred = params;
    unblurred.blur_sigma = 0;
    symmetry::detect_edges(source, unblurred, &edges);
  } else {
    cv::Canny(source, edges, params.canny_low, params.canny_high, 3);
  }
  return edges;
}

// Pixels worth running Canny on: the moving blocks' bounding rectangle plus a margin wide enough
// that the blur and Canny inside the blocks see the same neighbourhood as on the whole frame.
cv::Rect moving_region(const cv::Mat& blocks, int block_size, const cv::Size& image) {
  constexpr int kMargin = 8;
  std::vector<cv::Point> moving;
  cv::findNonZero(blocks, moving);
  if (moving.empty()) return {};
  const cv::Rect b = cv::boundingRect(moving);
  const cv::Rect px(b.x * block_size - kMargin, b.y * block_size - kMargin, b.width * block_size + 2 * kMargin,
                    b.height * block_size + 2 * kMargin);
  return px & cv::Rect(cv::Point(0, 0), image);
}

// Edge pixels inside moving blocks (the motion mask ANDed with the edge image), row-major.
symmetry::EdgeSet motion_masked_edges(const cv::Mat& grey, const BlockMotion& motion,
                                      const symmetry::EdgeParams& params) {
  symmetry::EdgeSet edges;
  edges.width = grey.cols;
  edges.height = grey.rows;
  const cv::Rect roi = moving_region(motion.blocks, motion.block_size, grey.size());
  if (roi.empty()) return edges;
  const cv::Mat edge_image = edge_pixels(grey(roi), params);
  for (int y = roi.y; y < roi.y + roi.height; ++y) {
    const uint8_t* e = edge_image.ptr<uint8_t>(y - roi.y) - roi.x;
    const uint8_t* moving = motion.blocks.ptr<uint8_t>(y / motion.block_size);
    for (int x = roi.x; x < roi.x + roi.width; ++x)
      if (e[x] && moving[x / motion.block_size]) edges.points.emplace_back(x, y);
  }
  return edges;
}
// Fraction of the blocks set in `object` that are set in `moving` (1 when `object` is empty or
// does not match: no evidence that the object stopped).
double moving_fraction(const cv::Mat& object, const cv::Mat& moving) {
  if (object.empty() || object.size() != moving.size()) return 1.0;
  int total = 0, hit = 0;
  for (int y = 0; y < object.rows; ++y) {
    const uint8_t* o = object.ptr<uint8_t>(y);
    const uint8_t* m = moving.ptr<uint8_t>(y);
    for (int x = 0; x < object.cols; ++x) {
      total += o[x] != 0;
      hit += o[x] != 0 && m[x] != 0;
    }
  }
  return total > 0 ? static_cast<double>(hit) / total : 1.0;
}

}  // namespace

const char* to_string(TrackStatus status) {
  switch (status) {
    case TrackStatus::Idle: return "idle";
    case TrackStatus::Initialising: return "initialising";
    case TrackStatus::Tracking: return "tracking";
    case TrackStatus::Lost: return "lost";
  }
  return "unknown";
}

void validate(const TrackerParams& p) {
  validate(p.motion);
  validate(p.kalman);
  validate(p.refine);
  symmetry::validate(p.edges);
  symmetry::validate(p.detector);
  require(p.detector.num_lines >= 1 && p.detector.num_lines <= 5,
          "tracker detector num_lines must be in [1, 5] (the start tries num_lines^3 associations)");
  require(p.start.min_blocks >= 1, "tracker start min_blocks must be >= 1");
  require(std::isfinite(p.start.jump_factor) && p.start.jump_factor >= 1, "tracker start jump_factor must be >= 1");
  require(p.start.baseline_smoothing > 0 && p.start.baseline_smoothing <= 1,
          "tracker start baseline_smoothing must be in (0, 1]");
  require(p.start.max_frames >= 3, "tracker start max_frames must be >= 3");
  require(std::isfinite(p.start.tie_margin) && p.start.tie_margin >= 0, "tracker start tie_margin must be >= 0");
  require(p.start.rearm_frames >= 0, "tracker start rearm_frames must be >= 0");
  require(p.start.reacquire_frames >= 0, "tracker start reacquire_frames must be >= 0");
  require(std::isfinite(p.gate_sigmas) && p.gate_sigmas > 0, "tracker gate_sigmas must be > 0");
  require(std::isfinite(p.min_half_width_deg) && p.min_half_width_deg >= 0.5 && p.min_half_width_deg <= 90,
          "tracker min_half_width_deg must be in [0.5, 90]");
  require(std::isfinite(p.still_fraction) && p.still_fraction >= 0 && p.still_fraction <= 1,
          "tracker still_fraction must be in [0, 1]");
  require(std::isfinite(p.support_weight) && p.support_weight >= 0, "tracker support_weight must be >= 0");
  require(p.max_missed_frames >= 1, "tracker max_missed_frames must be >= 1");
  require(p.max_rest_frames >= 0, "tracker max_rest_frames must be >= 0");
  require(p.max_frame_gap_us > 0, "tracker max_frame_gap_us must be > 0");
}

bool best_start(const std::vector<std::vector<LineMeasurement>>& frames, const KalmanParams& params,
                LineKalman* filter, double* total_gate_error, double tie_margin) {
  if (frames.empty()) return false;
  for (const auto& f : frames)
    if (f.empty()) return false;
  std::vector<size_t> pick(frames.size(), 0);
  double best_error = std::numeric_limits<double>::infinity();
  size_t best_rank = 0;
  LineKalman trial(params);
  for (;;) {
    // Try the association `pick` (one line index per frame; index = rank by votes).
    trial.initialise(frames[0][pick[0]]);
    double error = 0;
    bool gated = true;
    size_t rank = pick[0];
    for (size_t f = 1; f < frames.size() && gated; ++f) {
      trial.predict();
      const double e = trial.gate_error(frames[f][pick[f]]);
      gated = trial.in_gate(e);
      error += e;
      rank += pick[f];
      trial.update(frames[f][pick[f]]);
    }
    // Least accumulated gate error (thesis); near-ties go to the stronger lines.
    const bool better = error < best_error - tie_margin ||
                        (error <= best_error + tie_margin && (rank < best_rank || (rank == best_rank && error < best_error)));
    if (gated && better) {
      best_error = error;
      best_rank = rank;
      *filter = trial;
    }
    // Next association, like an odometer.
    size_t f = 0;
    while (f < frames.size() && ++pick[f] == frames[f].size()) pick[f++] = 0;
    if (f == frames.size()) break;
  }
  if (total_gate_error) *total_gate_error = best_error;
  return std::isfinite(best_error);
}

int associate(const LineKalman& filter, const std::vector<LineMeasurement>& lines, double support_weight,
              double* gate_error) {
  std::vector<double> errors(lines.size());
  double strongest = 0;
  for (size_t i = 0; i < lines.size(); ++i) {
    errors[i] = filter.gate_error(lines[i]);
    if (filter.in_gate(errors[i])) strongest = std::max(strongest, lines[i].votes);
  }
  int best = -1;
  double best_cost = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < lines.size(); ++i) {
    if (!filter.in_gate(errors[i])) continue;
    double cost = errors[i];  // the thesis: the lowest normalised innovation
    if (support_weight > 0 && strongest > 0 && lines[i].votes > 0)
      cost += support_weight * 2.0 * std::log(strongest / lines[i].votes);
    if (cost < best_cost) {
      best_cost = cost;
      best = static_cast<int>(i);
    }
  }
  if (gate_error && best >= 0) *gate_error = errors[best];
  return best;
}

std::vector<std::vector<LineMeasurement>> lines_near(const LineKalman& lost,
                                                     const std::vector<std::vector<LineMeasurement>>& frames) {
  std::vector<std::vector<LineMeasurement>> preferred;
  for (const auto& lines : frames) {
    std::vector<LineMeasurement> near;
    for (const LineMeasurement& line : lines)
      if (lost.in_gate(lost.gate_error(line))) near.push_back(line);
    preferred.push_back(near.empty() ? lines : near);
  }
  return preferred;
}

SymmetryTracker::SymmetryTracker(TrackerParams params)
    : params_(std::move(params)), reason_(kWaitingForFirstFrame), kalman_(params_.kalman), last_measured_track_(params_.kalman), lost_track_(params_.kalman) {
  validate(params_);
}

void SymmetryTracker::reset(TrackStatus status, const std::string& reason) {
  status_ = status;
  reason_ = reason;
  previous_.release();
  idle_baseline_ = 0;
  start_window_.clear();
  start_frames_ = 0;
  missed_ = 0;
  frames_since_loss_ = -1;  // the past frames are forgotten: any motion starts a track
  frames_since_lost_track_ = -1;
  object_blocks_.release();
  last_votes_ = 0;
  resting_ = 0;
}

void SymmetryTracker::restart(const std::string& reason) {
  reset(track_active(status_) ? TrackStatus::Lost : TrackStatus::Idle, reason);
}

void SymmetryTracker::start_at(const symmetry::Line& line) {
  LineMeasurement start;
  start.r = line.r;
  start.theta_deg = line.theta * kDegPerRad;
  kalman_.initialise_at_rest(normalise(start));
  last_measured_track_ = kalman_;
  status_ = TrackStatus::Tracking;
  reason_.clear();
  missed_ = 0;
  frames_since_loss_ = -1;
  frames_since_lost_track_ = -1;
  ++tracks_started_;
  start_window_.clear();
  start_frames_ = 0;
  object_blocks_.release();  // the first frame's motion about the line becomes the object's
  last_votes_ = 0;
  resting_ = 0;
}

TrackState SymmetryTracker::feed(const cv::Mat& frame, int64_t utime) {
  TrackState state;
  state.utime = utime;
  state.frame_index = frames_++;
  state.block_size = params_.motion.block_size;
  try {
    cv::Mat grey;
    if (accept_frame(frame, utime, &grey, &state)) {
      process(grey, &state);
      previous_ = grey;
      previous_utime_ = utime;
    }
  } catch (const std::exception& e) {
    // Nothing here should throw for any input; if something does, end the track loudly rather
    // than let one bad frame take the process down.
    reset(track_active(status_) ? TrackStatus::Lost : TrackStatus::Idle,
          std::string("internal error, tracker restarted: ") + e.what());
  }
  state.status = status_;
  state.tracks_started = tracks_started_;
  if (state.reason.empty()) state.reason = reason_;
  return state;
}

void SymmetryTracker::process(const cv::Mat& grey, TrackState* state) {
  Stopwatch watch;
  const BlockMotion motion = detect_block_motion(previous_, grey, params_.motion);
  state->ms.motion_ms = watch.lap_ms();
  state->blocks = motion.blocks;
  state->moving_blocks = motion.moving_blocks;
  age_lost_track();
  if (status_ == TrackStatus::Idle || status_ == TrackStatus::Lost) watch_for_start(motion);
  if (status_ == TrackStatus::Initialising) {
    initialise(grey, motion, state);
  } else if (status_ == TrackStatus::Tracking) {
    track(grey, motion, state);
  }
}

bool SymmetryTracker::accept_frame(const cv::Mat& frame, int64_t utime, cv::Mat* grey, TrackState* state) {
  state->width = frame.cols;
  state->height = frame.rows;
  // A skipped frame is reported in this frame's state only; the tracker's own reason stays.
  if (frame.empty() || frame.dims != 2) {
    state->reason = "empty frame skipped";
    return false;
  }
  if (frame.depth() != CV_8U || !(frame.channels() == 1 || frame.channels() == 3 || frame.channels() == 4)) {
    state->reason = "frame skipped: only 8-bit grey, BGR or BGRA frames are tracked";
    return false;
  }
  if (frame.channels() == 3) cv::cvtColor(frame, *grey, cv::COLOR_BGR2GRAY);
  else if (frame.channels() == 4) cv::cvtColor(frame, *grey, cv::COLOR_BGRA2GRAY);
  else *grey = frame.clone();  // kept as the next frame's I0: must not alias the caller's buffer

  if (!previous_.empty()) {
    const TrackStatus after = track_active(status_) ? TrackStatus::Lost : TrackStatus::Idle;
    std::ostringstream why;
    if (grey->size() != previous_.size()) {
      why << "image size changed from " << size_text(previous_.size()) << " to " << size_text(grey->size());
    } else if (utime <= previous_utime_) {
      why << "frame out of order: utime " << utime << " is not after " << previous_utime_;
    } else if (utime - previous_utime_ > params_.max_frame_gap_us) {
      why << "time jump of " << (utime - previous_utime_) * 1e-6 << " s between frames";
    }
    if (!why.str().empty()) {
      reset(after, why.str() + ": tracker restarted");
    }
  }
  if (previous_.empty()) {  // the first frame of a stream: nothing to difference against yet
    previous_ = *grey;
    previous_utime_ = utime;
    if (reason_ == kWaitingForFirstFrame) reason_ = "waiting for motion";
    return false;
  }
  return true;
}

void SymmetryTracker::watch_for_start(const BlockMotion& motion) {
  const double count = motion.moving_blocks;
  // After a loss, motion that went on through it counts as new once rearm_frames have passed.
  const bool after_loss = frames_since_loss_ >= 0;
  const bool rearmed = after_loss && params_.start.rearm_frames > 0 && ++frames_since_loss_ > params_.start.rearm_frames;
  const bool jump = count >= params_.start.min_blocks &&
                    (rearmed || count >= params_.start.jump_factor * idle_baseline_);
  if (jump) {
    status_ = TrackStatus::Initialising;
    reason_ = after_loss ? "re-acquiring: motion after the loss, collecting three frames for a new automatic start"
                         : "motion started: collecting three frames for the automatic start";
    frames_since_loss_ = -1;
    start_window_.clear();
    start_frames_ = 0;
    return;
  }
  const double w = params_.start.baseline_smoothing;
  idle_baseline_ = (1 - w) * idle_baseline_ + w * count;
  if (status_ == TrackStatus::Idle) reason_ = "waiting for motion";
}

std::vector<LineMeasurement> SymmetryTracker::detect_lines(const cv::Mat& grey, const BlockMotion& motion,
                                                           const AngleLimits& limits, TrackState* state) {
  std::vector<LineMeasurement> lines;
  state->limits = limits;
  try {
    Stopwatch watch;
    const symmetry::EdgeSet edges = motion_masked_edges(grey, motion, params_.edges);
    state->ms.edges_ms = watch.lap_ms();
    symmetry::Params p = params_.detector;
    p.theta_min_deg = limits.min_deg;
    p.theta_max_deg = limits.max_deg;
    symmetry::Detector detector(p, params_.edges);
    for (const auto& line : detector.detect(edges).lines)
      lines.push_back({line.r, line.theta * kDegPerRad, line.votes});
    state->ms.detect_ms = watch.lap_ms();
  } catch (const std::exception&) {
    lines.clear();  // a frame the detector cannot use offers no measurements
  }
  state->lines_detected = static_cast<int>(lines.size());
  state->measurements = lines;
  return lines;
}

void SymmetryTracker::initialise(const cv::Mat& grey, const BlockMotion& motion, TrackState* state) {
  const AngleLimits search{params_.detector.theta_min_deg, params_.detector.theta_max_deg};
  start_window_.push_back(detect_lines(grey, motion, search, state));
  ++start_frames_;
  if (start_window_.size() > 3) start_window_.erase(start_window_.begin());
  Stopwatch watch;
  double error = 0;
  if (start_window_.size() == 3 &&
      best_start(frames_since_lost_track_ >= 0 ? lines_near(lost_track_, start_window_) : start_window_, params_.kalman, &kalman_, &error, params_.start.tie_margin)) {
    frames_since_lost_track_ = -1;
    last_measured_track_ = kalman_;
    status_ = TrackStatus::Tracking;
    reason_.clear();
    missed_ = 0;
    ++tracks_started_;
    resting_ = 0;
    last_votes_ = state->measurements.empty() ? 0 : state->measurements.front().votes;
    state->measurement_used = true;
    state->gate_error = error;
    state->ms.kalman_ms = watch.lap_ms();
    describe_estimate(motion, state);
    return;
  }
  state->ms.kalman_ms = watch.lap_ms();
  if (start_frames_ >= params_.start.max_frames) {
    status_ = TrackStatus::Idle;
    reason_ = "automatic start failed: no consistent symmetry line in " + std::to_string(start_frames_) +
              " frames of motion";
    idle_baseline_ = motion.moving_blocks;  // a new jump in motion tries again, or any after rearm_frames
    frames_since_loss_ = 0;
  }
}

void SymmetryTracker::track(const cv::Mat& grey, const BlockMotion& motion, TrackState* state) {
  Stopwatch watch;
  state->object_motion = moving_fraction(object_blocks_, motion.blocks);
  if (state->object_motion < params_.still_fraction) {
    state->ms.kalman_ms = watch.lap_ms();
    hold(grey, motion, state);
    return;
  }
  resting_ = 0;
  kalman_.predict();
  const AngleLimits limits = angle_limits(kalman_.line().theta_deg, kalman_.theta_sigma_deg(), params_.gate_sigmas,
                                          params_.min_half_width_deg);
  state->ms.kalman_ms = watch.lap_ms();
  const std::vector<LineMeasurement> lines = detect_lines(grey, motion, limits, state);
  watch.restart();
  double best_error = 0;
  const int best = associate(kalman_, lines, params_.support_weight, &best_error);
  if (best >= 0) {
    kalman_.update(lines[best]);
    missed_ = 0;
    last_votes_ = lines[best].votes;
    last_measured_track_ = kalman_;
    state->measurement_used = true;
    state->gate_error = best_error;
    reason_.clear();
  } else if (params_.max_rest_frames > 0 && measure_in_place(grey, motion, state)) {
    missed_ = 0;  // the object's own line is where predicted, moving or not
    reason_ = "measured in place: no moving line inside the gate, the object's own line is there";
  } else {
    ++missed_;
    reason_ = "predicting: no line inside the validation gate (" + std::to_string(lines.size()) + " detected)";
  }
  state->missed_frames = missed_;
  state->ms.kalman_ms += watch.lap_ms();
  describe_estimate(motion, state);

  const double half_diagonal = 0.5 * std::hypot(grey.cols, grey.rows);
  if (missed_ >= params_.max_missed_frames) {
    end_track("no symmetry line inside the validation gate for " + std::to_string(missed_) + " frames", state);
  } else if (!kalman_.state().allFinite() || std::fabs(kalman_.line().r) > half_diagonal) {
    end_track("the tracked symmetry line left the image", state);
  }
}

// The object stopped: hold the line where it is and measure nothing from the motion (a moving line
// now belongs to something else). The blocks of the last motion stay the object's. A held frame
// counts as a missed one unless the object's own line is still there (resting).
void SymmetryTracker::hold(const cv::Mat& grey, const BlockMotion& motion, TrackState* state) {
  Stopwatch watch;
  kalman_.hold();
  const bool resting = params_.max_rest_frames > 0 && measure_in_place(grey, motion, state);
  if (resting) {
    kalman_.rest();
    ++resting_;
    reason_ = "holding: the object rests where it stopped (" + std::to_string(resting_) + " frames)";
  } else {
    resting_ = 0;
    ++missed_;
    reason_ = "holding: no motion at the tracked object";
  }
  state->holding = true;
  state->resting_frames = resting_;
  state->missed_frames = missed_;
  state->ms.kalman_ms = watch.lap_ms();
  // The box and blocks reported are those of the object's last motion, where it now stands.
  const cv::Mat object = object_blocks_;
  BlockMotion held = motion;
  if (!object.empty()) held.blocks = object;
  describe_estimate(held, state);
  object_blocks_ = object;
  if (missed_ >= params_.max_missed_frames)
    end_track("no symmetry line inside the validation gate for " + std::to_string(missed_) + " frames", state);
  else if (resting_ > params_.max_rest_frames)
    end_track("the object rested for more than " + std::to_string(params_.max_rest_frames) + " frames", state);
}

// The object's own symmetry is still where the track predicts it: the edges inside the track's
// blocks (all of them, not only moving ones) give a line inside the validation gate with at least
// half the support of the last line used; it updates the filter. Used when the motion gives no
// gated line: a still object (nothing moves), or one whose blocks another object's motion covers.
// An object that vanished or was covered leaves no such line (the detector's votes of a background
// pattern rarely reach the object's). The frame's reported measurements stay the motion's.
bool SymmetryTracker::measure_in_place(const cv::Mat& grey, const BlockMotion& motion, TrackState* state) {
  if (object_blocks_.empty() || last_votes_ <= 0) return false;
  BlockMotion object = motion;
  object.blocks = object_blocks_;
  const AngleLimits limits = angle_limits(kalman_.line().theta_deg, kalman_.theta_sigma_deg(), params_.gate_sigmas,
                                          params_.min_half_width_deg);
  TrackState scratch;
  std::vector<LineMeasurement> lines = detect_lines(grey, object, limits, &scratch);
  state->ms.edges_ms += scratch.ms.edges_ms;
  state->ms.detect_ms += scratch.ms.detect_ms;
  lines.erase(std::remove_if(lines.begin(), lines.end(),
                             [&](const LineMeasurement& l) { return l.votes < 0.5 * last_votes_; }),
              lines.end());
  double gate_error = 0;
  const int best = associate(kalman_, lines, params_.support_weight, &gate_error);
  if (best < 0) return false;
  // The object's own line measures it: the estimate stays sharp and the gate narrow, so a
  // neighbour that moves into the track's blocks cannot be taken for it.
  kalman_.update(lines[best]);
  last_measured_track_ = kalman_;
  state->measurement_used = true;
  state->gate_error = gate_error;
  return true;
}

void SymmetryTracker::end_track(const std::string& reason, TrackState* state) {
  status_ = TrackStatus::Lost;
  reason_ = reason;
  idle_baseline_ = state->moving_blocks;  // a new start needs a new jump in motion, or rearm_frames
  frames_since_loss_ = 0;
  start_window_.clear();
  // Remember where the object was last measured (not where the predict-only frames carried the
  // line): a new start prefers lines there for a while, in a gate grown by the frames since.
  lost_track_ = last_measured_track_;
  lost_track_.hold();
  for (int i = 0; i < missed_; ++i) lost_track_.predict();
  frames_since_lost_track_ = 0;
  missed_ = 0;
  object_blocks_.release();
  last_votes_ = 0;
  resting_ = 0;
}

void SymmetryTracker::age_lost_track() {
  if (frames_since_lost_track_ < 0) return;
  if (++frames_since_lost_track_ > params_.start.reacquire_frames) {
    frames_since_lost_track_ = -1;
    return;
  }
  lost_track_.predict();  // at rest: the line stays, its covariance (and so the gate) grows
}

void SymmetryTracker::describe_estimate(const BlockMotion& motion, TrackState* state) {
  Stopwatch watch;
  const LineMeasurement est = normalise(kalman_.line());
  state->has_estimate = true;
  state->line = symmetry::Line{};
  state->line.r = est.r;
  state->line.theta = est.theta_deg / kDegPerRad;
  symmetry::border_endpoints(state->line.r, state->line.theta, state->width, state->height,
                             &state->line.end1, &state->line.end2);
  state->line.seg1 = state->line.end1;
  state->line.seg2 = state->line.end2;
  state->covariance = to_radians(kalman_.line_covariance());
  state->blocks = refine_blocks(motion.blocks, motion.block_size, state->width, state->height, state->line.r,
                                state->line.theta, params_.refine);
  const RotatedBox box =
      rotated_box(state->blocks, motion.block_size, state->width, state->height, state->line.r, state->line.theta);
  state->has_box = box.valid;
  if (box.valid) state->box = box.corners;
  object_blocks_ = state->blocks.clone();  // state->blocks goes to the caller
  state->ms.refine_ms = watch.elapsed_ms();
}

}  // namespace nudge::tracking
