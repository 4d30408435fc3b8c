#include "nudge/supervisor/supervisor.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <future>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/triangulation.hpp"
#include "nudge/robot/command_planner.hpp"
#include "nudge/segmentation/motion.hpp"
#include "nudge/supervisor/grasp.hpp"
#include "nudge/timing.hpp"
#include "nudge/worker.hpp"

namespace nudge::supervisor {

namespace {

constexpr double kMicro = 1e6;

std::string seconds_text(double seconds) {
  char text[32];
  std::snprintf(text, sizeof text, "%g s", seconds);
  return text;
}

// How many rows of a 0/255 mask hold a pixel.
int rows_with_pixels(const cv::Mat& mask) {
  int rows = 0;
  for (int y = 0; y < mask.rows; ++y) rows += cv::countNonZero(mask.row(y)) > 0;
  return rows;
}

double median(std::vector<double> values) {
  std::nth_element(values.begin(), values.begin() + values.size() / 2, values.end());
  return values[values.size() / 2];
}

}  // namespace

const char* to_string(State state) {
  switch (state) {
    case State::Idle: return "IDLE";
    case State::FindCandidates: return "FIND_CANDIDATES";
    case State::Nudge: return "NUDGE";
    case State::Track: return "TRACK";
    case State::Segment: return "SEGMENT";
    case State::Done: return "DONE";
    case State::Failed: return "FAILED";
    case State::WaitServices: return "WAIT_SERVICES";
    case State::Paused: return "PAUSED";
    case State::SnapshotBefore: return "SNAPSHOT_BEFORE";
    case State::SnapshotAfter: return "SNAPSHOT_AFTER";
    case State::Choose: return "CHOOSE";
    case State::Home: return "HOME";
    case State::Grasp: return "GRASP";
    case State::Rotate: return "ROTATE";
    case State::Learn: return "LEARN";
    case State::Recognise: return "RECOGNISE";
    case State::Place: return "PLACE";
  }
  return "?";
}

const char* to_string(Outcome outcome) {
  switch (outcome) {
    case Outcome::Segmented: return "segmented";
    case Outcome::NoMotion: return "no motion";
    case Outcome::Tipped: return "tipped or lost";
    case Outcome::Refused: return "arm refused";
    case Outcome::SnapshotLost: return "snapshot lost";
    case Outcome::ArmFailed: return "arm failed";
    case Outcome::Aborted: return "aborted";
    case Outcome::SegmentationFailed: return "segmentation failed";
    case Outcome::TrackerLost: return "tracker lost";
    case Outcome::Known: return "already known";
  }
  return "?";
}

Supervisor::Supervisor(Config config, SceneGeometry scene, ArmSetup arm, SegmentFunction segment)
    : config_(std::move(config)), scene_(std::move(scene)), arm_(std::move(arm)), segment_(std::move(segment)) {
  if (!segment_) throw std::invalid_argument("supervisor: a segmentation function is required");
  if (config_.survey_frames <= 0 || config_.survey_lines <= 0 || config_.max_attempts <= 0)
    throw std::invalid_argument("supervisor: survey_frames, survey_lines and max_attempts must be positive");
  if (config_.agreement_lines <= 0 || !(config_.explored_line_px > 0))
    throw std::invalid_argument("supervisor: agreement_lines and explored_line_px must be positive");
  if (config_.views <= 0 || !(config_.view_step_deg > 0))
    throw std::invalid_argument("supervisor: views and view_step_deg must be positive");
  if (!(config_.settle_s >= 0 && config_.max_settle_s >= config_.settle_s))
    throw std::invalid_argument("supervisor: settle_s must be >= 0 and max_settle_s >= settle_s");
  if (config_.segmentation_retries < 0) throw std::invalid_argument("supervisor: segmentation_retries must be >= 0");
  if (!(config_.retry_still_line_px >= 0)) throw std::invalid_argument("supervisor: retry_still_line_px must be >= 0");
  if (!(config_.refine_target_max_m >= 0 && config_.refine_target_max_m <= 0.2))
    throw std::invalid_argument("supervisor: refine_target_max_m must be in [0, 0.2] m");
  if (!(config_.refine_window_px > 0)) throw std::invalid_argument("supervisor: refine_window_px must be > 0");
  validate(config_.height);
  joints_ = arm_.home();
}

std::vector<Output> Supervisor::take_outputs() {
  std::vector<Output> out;
  out.swap(outputs_);
  return out;
}

void Supervisor::start(int64_t now, int64_t first_command_seq) {
  next_seq_ = first_command_seq;
  enter(State::WaitServices, now, "waiting for every required service's heartbeat");
  if (silent_.empty()) survey(now);
}

bool Supervisor::timed_out(double seconds, int64_t now) const {
  return static_cast<double>(now - entered_) > seconds * kMicro;
}

bool Supervisor::in_attempt() const { return attempt_ != nullptr; }

// With `track` the trackers, once motion started them, decide where the object rests and whether
// it stands; with `track_trace` alone they are only watched.
bool Supervisor::trackers_decide() const { return config_.track && tracking_started_; }

void Supervisor::enter(State state, int64_t now, const std::string& reason) {
  state_ = state;
  entered_ = now;
  report_.state = state;
  report_.reason = reason;
  report_.segmented = summary_.segmented;
  // The attempt under way has not failed (yet): only ended ones count.
  report_.failed_attempts = summary_.attempts - (attempt_ ? 1 : 0) - summary_.segmented;
  outputs_.push_back(report_);
}

void Supervisor::finish(State state, const std::string& reason, int64_t now) {
  summary_.end_reason = reason;
  enter(state, now, reason);
  outputs_.push_back(Finished{summary_});
}

// ---- the loop ----

void Supervisor::survey(int64_t now, const std::string& why, double max_line_tilt_deg) {
  if (summary_.attempts >= config_.max_attempts) {
    finish(State::Done, "attempt limit reached (" + std::to_string(config_.max_attempts) + " nudges)", now);
    return;
  }
  ++summary_.surveys;
  request_time_ = now;
  wide_survey_ = max_line_tilt_deg > 0;
  for (auto& lines : survey_lines_) lines.clear();
  sighted_.clear();
  char wide[64] = "";
  if (wide_survey_) std::snprintf(wide, sizeof wide, ", lines up to %.0f deg from upright", max_line_tilt_deg);
  enter(State::FindCandidates, now,
        (why.empty() ? std::string() : why + "; ") + "surveying: candidates from " + std::to_string(config_.survey_frames) +
            " stereo pairs" + wide);
  std::vector<Eigen::Vector3d> explored;
  for (const ExploredObject& object : standing_) explored.push_back(object.place);
  outputs_.push_back(CandidatesRequest{config_.survey_frames, config_.survey_lines, explored, max_line_tilt_deg});
}

// The choice's parameters: with learning, a push that leaves the object graspable comes first.
TargetParams Supervisor::target_params() const {
  TargetParams params = config_.targets;
  if (config_.graspable_push_first && learning_enabled()) params.rest_travel = config_.push_travel_m;
  return params;
}

void Supervisor::choose(int64_t now) {
  const Eigen::Vector3d camera = scene_.right_camera_in_world();
  std::vector<Rejection> hidden;
  const std::vector<Candidate> visible = drop_hidden_behind_arm_base(hidden);
  TargetChoice choice = choose_target(visible, history(), camera, arm_, joints_, target_params());
  choice.rejected.insert(choice.rejected.end(), hidden.begin(), hidden.end());
  summary_.rejections.clear();
  for (const Rejection& r : choice.rejected) ++summary_.rejections[r.reason];
  report_.num_candidates = static_cast<int>(candidates_.size());
  report_.rejected = static_cast<int>(choice.rejected.size());
  if (!choice.found) {
    std::string why = candidates_.empty() ? "no candidate found on the table" : "no nudgeable candidate left";
    const bool any_new = std::any_of(choice.rejected.begin(), choice.rejected.end(),
                                     [](const Rejection& r) { return r.reason != "already explored"; });
    if (any_new) why += " (" + choice.rejected.back().reason + ")";
    if (!wide_survey_ && config_.wide_survey_tilt_deg > 0) {
      survey(now, why + ": a second look", config_.wide_survey_tilt_deg);
      return;
    }
    finish(State::Done, why, now);
    return;
  }
  nudge_seq_ = 0;  // set when the nudge is commanded: an attempt that ends before needs no homing
  attempt_ = std::make_unique<Attempt>();
  attempt_->number = ++summary_.attempts;
  attempt_->target = choice.target;
  attempt_->direction = choice.direction;
  attempt_->plan = choice.plan;
  attempt_->height_limit = choice.height_limit;
  attempt_->candidates = candidates_;
  attempt_->rejected = choice.rejected;
  attempt_->started = now;
  attempt_->learn = learning_enabled();
  report_.attempt = attempt_->number;
  report_.candidate_index = choice.target.index;
  report_.target = choice.target.position;
  request_still(State::SnapshotBefore, now, choice.note);
}

// The attempt's target and push become `choice`'s (a target chosen again before the nudge).
void Supervisor::take_choice(const TargetChoice& choice) {
  Attempt& a = *attempt_;
  a.target = choice.target;
  a.direction = choice.direction;
  a.plan = choice.plan;
  a.height_limit = choice.height_limit;
  report_.candidate_index = choice.target.index;
  report_.target = choice.target.position;
}

// Config::rival_by_foot: the target's depth checked against its before line's foot, and a
// candidate on the same right-camera line at the depth the foot shows nudged instead.
void Supervisor::prefer_rival_at_the_lines_foot() {
  Attempt& a = *attempt_;
  const std::optional<size_t> rival = rivals_at_the_lines_foot(a);
  if (!config_.rival_by_foot || !rival) return;
  auto misfit = [&](double d) { return std::abs(d - config_.foot_depth_typical_m); };
  const auto& [candidate, depth] = a.rivals[*rival];
  if (misfit(depth) > config_.rival_max_misfit_m || misfit(depth) > misfit(*a.foot_depth_m) - config_.rival_margin_m) return;
  // Planned as the survey plans every push: the other candidates are obstacles, all but the target
  // it replaces (on the hypothesis that both are this one object, placed once wrongly).
  std::vector<Candidate> others;
  for (const Candidate& c : a.candidates)
    if (c.index != a.target.index) others.push_back(c);
  const auto at = std::find_if(others.begin(), others.end(), [&](const Candidate& c) { return c.index == candidate.index; });
  if (at == others.end()) return;
  const TargetChoice choice = choose_push_for(others, static_cast<size_t>(at - others.begin()), history(),
                                              scene_.right_camera_in_world(), arm_, joints_, target_params());
  if (!choice.found) return;  // the rival is explored or has no clear push: the survey's choice stands
  a.replaced = a.target;
  a.replaced_foot_depth_m = *a.foot_depth_m;
  a.foot_depth_m = depth;
  take_choice(choice);
  a.before_line.reset();
  a.measured_height.reset();
  a.before_line_left.reset();
  before_lines();  // the new target's prediction
}

bool Supervisor::before_stills_of_both_cameras() const {
  return state_ == State::SnapshotBefore && config_.refine_target_max_m > 0;
}

namespace {

// `line`, found in a still of `size`, in the camera's calibration image (the stills are the same
// camera at another resolution).
symmetry::Line at_calibration(const geometry::Camera& camera, const symmetry::Line& line, cv::Size size) {
  const Eigen::Vector2d a = to_calibration(camera, line.end1, size), b = to_calibration(camera, line.end2, size);
  return line_through({a.x(), a.y()}, {b.x(), b.y()}, {camera.width, camera.height});
}

}  // namespace

// Config::refine_target_max_m: the target placed anew from its lines in both before stills, and
// its push planned again there.
void Supervisor::refine_target_by_stills() {
  Attempt& a = *attempt_;
  if (config_.refine_target_max_m <= 0 || a.before.empty() || a.before_left.empty()) return;
  const auto predicted_left = scene_.left_axis_line(a.target.position, config_.object_height_m, config_.still_size);
  const auto predicted_right = scene_.right_axis_line(a.target.position, config_.object_height_m, config_.still_size);
  if (!predicted_left || !predicted_right) return;
  LineSearchParams search = config_.line_search;
  search.window_px = config_.refine_window_px;
  const auto left = find_line_near(a.before_left, *predicted_left, search, base_column_lines(0));
  const auto right = find_line_near(a.before, *predicted_right, search, base_column_lines(1));
  if (!left || !right) return;
  const geometry::StereoRig& rig = scene_.rig();
  const auto axis = geometry::triangulate_axis(rig, at_calibration(rig.left, *left, config_.still_size),
                                               at_calibration(rig.right, *right, config_.still_size));
  if (!axis) return;
  const auto hit = geometry::check_axis(*axis, scene_.table());
  if (!hit) return;
  Eigen::Vector3d place = scene_.right_to_world(hit->point);
  place.z() = 0;
  if ((place - a.target.position).head<2>().norm() > config_.refine_target_max_m) return;  // another object's lines
  std::vector<Candidate> candidates = a.candidates;
  const auto target = std::find_if(candidates.begin(), candidates.end(), [&](const Candidate& c) { return c.index == a.target.index; });
  if (target == candidates.end()) return;
  target->position = place;
  const TargetChoice choice = choose_push_for(candidates, static_cast<size_t>(target - candidates.begin()), history(),
                                              scene_.right_camera_in_world(), arm_, joints_, target_params());
  if (!choice.found) return;  // no push plans there: the survey's stands
  a.surveyed_at = a.target.position;
  take_choice(choice);
}

// Sets the attempt's foot_depth_m and rivals (the survey's candidates on the target's right-camera
// line, with their depths beyond its before line's foot); the index of the rival nearest the
// typical depth, or nothing.
std::optional<size_t> Supervisor::rivals_at_the_lines_foot(Attempt& a) const {
  if (!a.before_line) return std::nullopt;
  auto depth = [&](const Candidate& c) { return depth_beyond_line_foot(scene_, *a.before_line, c.position, config_.still_size); };
  auto misfit = [&](double d) { return std::abs(d - config_.foot_depth_typical_m); };
  a.foot_depth_m = depth(a.target);
  const auto target_line = scene_.right_axis_line(a.target.position, config_.object_height_m, config_.frame_size);
  if (!a.foot_depth_m || !target_line) return std::nullopt;
  const double max_angle = config_.agreement_angle_deg * M_PI / 180;
  std::vector<Rejection> hidden;
  std::optional<size_t> best;
  for (const Candidate& c : drop_hidden_behind_arm_base(hidden)) {
    if (c.index == a.target.index) continue;
    const auto line = scene_.right_axis_line(c.position, config_.object_height_m, config_.frame_size);
    if (!line || !lines_agree(*line, *target_line, max_angle, config_.agreement_offset_px)) continue;
    const auto d = depth(c);
    if (!d) continue;
    a.rivals.emplace_back(c, *d);
    if (!best || misfit(*d) < misfit(a.rivals[*best].second)) best = a.rivals.size() - 1;
  }
  return best;
}

// The horizontal direction from the right camera to a point on the table.
Eigen::Vector2d Supervisor::viewing_ray(const Eigen::Vector3d& at) const {
  const Eigen::Vector2d ray = (at - scene_.right_camera_in_world()).head<2>();
  return ray.norm() > 1e-9 ? Eigen::Vector2d(ray.normalized()) : Eigen::Vector2d::UnitX();
}

// Two axes on the table that one camera sees as one line (a stereo mismatch of the other camera
// puts the same object at another depth along this camera's ray).
bool Supervisor::same_object_in_a_camera(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  if ((a - b).head<2>().norm() > config_.same_object_depth_m) return false;
  const double max_angle = config_.agreement_angle_deg * M_PI / 180;
  const auto la = scene_.left_axis_line(a, config_.object_height_m, config_.frame_size);
  const auto lb = scene_.left_axis_line(b, config_.object_height_m, config_.frame_size);
  const auto ra = scene_.right_axis_line(a, config_.object_height_m, config_.frame_size);
  const auto rb = scene_.right_axis_line(b, config_.object_height_m, config_.frame_size);
  return (la && lb && lines_agree(*lb, *la, max_angle, config_.agreement_offset_px)) ||
         (ra && rb && lines_agree(*rb, *ra, max_angle, config_.agreement_offset_px));
}

// The arm's base column (at the world origin) is symmetric too: a stereo mismatch of its line puts
// a candidate behind it on its line in one camera (dev runs: (-232, -34), (-176, -25) mm, nudged
// for nothing). That camera cannot see anything standing there: the column hides it.
std::vector<Candidate> Supervisor::drop_hidden_behind_arm_base(std::vector<Rejection>& rejected) const {
  const double max_angle = config_.agreement_angle_deg * M_PI / 180;
  const Eigen::Vector3d base = Eigen::Vector3d::Zero();
  const Eigen::Vector3d cameras[2] = {scene_.right_to_world(scene_.rig().left_centre()), scene_.right_camera_in_world()};
  std::vector<Candidate> visible;
  for (const Candidate& c : candidates_) {
    bool hidden = false;
    for (int camera = 0; camera < 2 && !hidden; ++camera) {
      const auto of_base = axis_line_in(camera, base, config_.frame_size);
      const auto of_candidate = axis_line_in(camera, c.position, config_.frame_size);
      const bool farther = (c.position - cameras[camera]).head<2>().norm() > (base - cameras[camera]).head<2>().norm();
      hidden = farther && of_base && of_candidate && lines_agree(*of_candidate, *of_base, max_angle, config_.agreement_offset_px);
    }
    if (hidden)
      rejected.push_back({c.index, c.position, "behind the arm's base in a camera (a stereo mismatch of its column)"});
    else
      visible.push_back(c);
  }
  return visible;
}

std::optional<symmetry::Line> Supervisor::axis_line_in(int camera, const Eigen::Vector3d& foot, cv::Size size) const {
  return camera == 0 ? scene_.left_axis_line(foot, config_.object_height_m, size)
                     : scene_.right_axis_line(foot, config_.object_height_m, size);
}

std::vector<symmetry::Line> Supervisor::base_column_lines(int camera) const {
  if (config_.line_search.not_object_px <= 0) return {};
  const auto line = axis_line_in(camera, Eigen::Vector3d::Zero(), config_.still_size);  // the base at the world origin
  return line ? std::vector<symmetry::Line>{*line} : std::vector<symmetry::Line>{};
}

// The places already explored, and this survey's candidates that are a rested object seen at
// another depth: the object nudged before is remembered by where it now stands.
std::vector<Eigen::Vector3d> Supervisor::explored_with_ray_mates() const {
  std::vector<Eigen::Vector3d> explored = explored_;
  for (const Candidate& c : candidates_)
    for (const Rested& object : rested_)
      if (same_object_in_a_camera(c.position, object.place) ||
          ((c.position - object.place).head<2>().norm() <= config_.same_object_depth_m &&
           share_of_mask_rows_on_line(c.position, object) >= config_.same_object_mask_share)) {
        explored.push_back(c.position);
        break;
      }
  return explored;
}

double Supervisor::share_of_mask_rows_on_line(const Eigen::Vector3d& foot, const Rested& object) const {
  const cv::Mat& mask = object.mask;
  const cv::Rect& box = object.box;
  if (mask.empty()) return 0.0;
  const auto bottom = scene_.project_right(Eigen::Vector3d(foot.x(), foot.y(), 0.0), mask.size());
  const auto top = scene_.project_right(Eigen::Vector3d(foot.x(), foot.y(), config_.object_height_m), mask.size());
  if (box.empty() || !bottom || !top || std::fabs(top->y - bottom->y) < 1.0) return 0.0;
  const int reach = 2;  // px either side: the line's rounding and the mask's ragged edge
  int on = 0;
  for (int y = box.y; y < box.y + box.height; ++y) {
    const double t = (y - bottom->y) / (top->y - bottom->y);
    const int x = cvRound(bottom->x + t * (top->x - bottom->x));
    const int from = std::max(x - reach, 0), to = std::min(x + reach, mask.cols - 1);
    if (from <= to && cv::countNonZero(mask.row(y).colRange(from, to + 1)) > 0) ++on;
  }
  return static_cast<double>(on) / box.height;
}

void Supervisor::request_still(State state, int64_t now, const std::string& note) {
  request_time_ = now;
  std::string reason = state == State::SnapshotBefore ? "still before the nudge of candidate " + std::to_string(attempt_->target.index) +
                                                            " at " + millimetres(attempt_->target.position)
                                                      : "still after the nudge";
  if (!note.empty()) reason += " (" + note + ")";
  enter(state, now, reason);
  ask_for_still(now, true);
}

void Supervisor::ask_for_still(int64_t now, bool first) {
  still_asked_ = now;
  still_requests_ = first ? 1 : still_requests_ + 1;
  outputs_.push_back(SnapshotRequest{state_ != State::Rotate && (attempt_->learn || before_stills_of_both_cameras())});
}

// Asks again for a still that has not come within snapshot_retry_s of the last request, while
// the step's snapshot_timeout_s lasts. Returns whether the step timed out.
bool Supervisor::still_overdue(int64_t now) {
  if (timed_out(config_.snapshot_timeout_s, now)) return true;
  if (static_cast<double>(now - still_asked_) > config_.snapshot_retry_s * kMicro) ask_for_still(now, false);
  return false;
}

std::string Supervisor::still_requests_text() const {
  return " (asked " + std::to_string(still_requests_) + (still_requests_ == 1 ? " time" : " times") + " in " +
         seconds_text(config_.snapshot_timeout_s) + ")";
}

// A push that clears only objects up to a height (TargetChoice::height_limit): the height to tell
// the arm, or nothing when the object measures taller or was not measured (the attempt has then
// ended with the reason).
std::optional<double> Supervisor::height_to_clear(int64_t now) {
  Attempt& a = *attempt_;
  if (a.height_limit <= 0) return 0.0;  // the arm's default: the tallest object expected
  const std::string limit = std::to_string(std::lround(a.height_limit * 1e3)) + " mm tall";
  if (!a.measured_height) {
    end_attempt(Outcome::Refused, "the push clears only an object " + limit + ", and the object's height was not measured in the still", now);
    return std::nullopt;
  }
  const double needed = *a.measured_height + config_.height.margin_m;
  if (needed > a.height_limit) {
    end_attempt(Outcome::Refused, "the object measures " + std::to_string(std::lround(*a.measured_height * 1e3)) +
                                      " mm tall in the still; the push clears only an object " + limit, now);
    return std::nullopt;
  }
  a.pushed_object_height = needed;
  return needed;
}

void Supervisor::start_nudge(int64_t now) {
  const std::optional<double> object_height = height_to_clear(now);
  if (!object_height) return;
  const Attempt& a = *attempt_;
  const auto line = scene_.right_axis_line(a.target.position, config_.object_height_m, config_.frame_size);
  const auto foot = scene_.project_right(a.target.position, config_.frame_size);
  const auto top = scene_.project_right(a.target.position + Eigen::Vector3d(0, 0, config_.motion_rows_height_m), config_.frame_size);
  const auto ahead = scene_.project_right(a.target.position + 0.03 * a.direction, config_.frame_size);
  if (!line || !foot || !top || !ahead) {
    end_attempt(Outcome::Refused, "the target is not in the right camera's view", now);
    return;
  }
  watch_ = std::make_unique<MotionWatch>(*line, *ahead - *foot, static_cast<int>(std::min(top->y, foot->y)) - 8,
                                         static_cast<int>(std::max(top->y, foot->y)) + 8, config_.frame_size, config_.motion);
  target_lines_[0] = scene_.left_axis_line(a.target.position, config_.object_height_m, config_.frame_size);
  target_lines_[1] = line;
  tracking_started_ = false;
  for (int camera = 0; camera < 2; ++camera) {
    trackers_[camera].reset();
    last_track_[camera] = tracking::TrackState{};
    track_lost_[camera].clear();
    track_done_[camera] = false;
    if ((config_.track || config_.track_trace) && target_lines_[camera]) trackers_[camera] = std::make_unique<tracking::SymmetryTracker>(config_.tracker);
  }
  nudge_seq_ = next_seq_++;
  std::string rival;
  if (a.replaced) {
    char text[200];
    std::snprintf(text, sizeof text, " instead of candidate %d at %s on its right-camera line: they stand %.0f and %.0f mm beyond "
                  "the foot of the line in the still", a.replaced->index, millimetres(a.replaced->position).c_str(),
                  1e3 * *a.foot_depth_m, 1e3 * a.replaced_foot_depth_m);
    rival = text;
  }
  enter(State::Nudge, now, "nudging candidate " + std::to_string(a.target.index) + " at " + millimetres(a.target.position) + rival);
  outputs_.push_back(NudgeCommand{nudge_seq_, a.target.position, a.direction, *object_height});
}

void Supervisor::verify(int64_t now) {
  Attempt& a = *attempt_;
  a.motion_frames = watch_ ? watch_->frames_with_motion() : 0;
  a.motion_blocks = watch_ ? watch_->max_blocks() : 0;
  if (!watch_ || !watch_->moved()) {
    end_attempt(Outcome::NoMotion, "no motion after nudge: nothing stood there (phantom candidate)", now);
    return;
  }
  const bool placed = trackers_decide() ? verify_by_tracking(now) : verify_by_axes(now);
  if (!placed) return;  // the attempt has ended with its reason
  const double moved = (*a.rest - a.target.position).head<2>().norm();
  if (moved < config_.min_displacement_m) {
    end_attempt(Outcome::NoMotion, "the object moved only " + std::to_string(static_cast<int>(std::lround(moved * 1e3))) + " mm", now);
    return;
  }
  // The after still is taken with the arm parked where it was for the before still (at home):
  // the arm then makes no difference between the two.
  nudge_seq_ = 0;
  park(now, a.rest_from_still ? "object not placed by the settled axes (" + a.settle_note +
                                    "): parking the arm to look for it along the push in the after still"
                              : "object at rest at " + millimetres(*a.rest) + ": parking the arm before the after still");
}

void Supervisor::park(int64_t now, const std::string& why) {
  arm_away_ = false;
  home_seq_ = next_seq_++;
  after_home_ = why;
  enter(State::Home, now, why);
  outputs_.push_back(HomeCommand{home_seq_});
}

void Supervisor::parked(int64_t now, const std::string& how) {
  if (attempt_) {
    request_still(State::SnapshotAfter, now, how);
  } else {
    survey(now, after_home_ + (how.empty() ? "" : "; " + how));
  }
}

// The thesis' check: both trackers still on the object, their lines triangulated to an upright
// axis on the table; its foot is where the object came to rest.
bool Supervisor::verify_by_tracking(int64_t now) {
  Attempt& a = *attempt_;
  static const char* kCameraNames[2] = {"left", "right"};
  for (int camera = 0; camera < 2; ++camera) {
    const tracking::TrackState& t = last_track_[camera];
    if (!track_lost_[camera].empty() || !t.has_estimate) {
      end_attempt(Outcome::TrackerLost, std::string("tracker lost in the ") + kCameraNames[camera] + " camera: " +
                                            (track_lost_[camera].empty() ? "no estimate" : track_lost_[camera]), now);
      return false;
    }
    a.tracked[camera] = t.line;
  }
  geometry::AxisFilter any_tilt;
  any_tilt.max_tilt_deg = 90;  // judged below, with the reason
  any_tilt.max_range_m = 10;
  const geometry::PairingResult pair =
      geometry::triangulate_pairings(scene_.rig(), {*a.tracked[0]}, {*a.tracked[1]}, &scene_.table(), any_tilt);
  if (pair.axes.empty() || !pair.axes[0].hit) {
    end_attempt(Outcome::TrackerLost, "the tracked lines do not meet in an axis on the table" +
                                          (pair.rejections.empty() ? std::string() : ": " + pair.rejections[0]), now);
    return false;
  }
  const geometry::TableHit& hit = *pair.axes[0].hit;
  a.rest_tilt_deg = hit.tilt_deg;
  if (hit.tilt_deg > config_.upright_max_tilt_deg) {
    char text[96];
    std::snprintf(text, sizeof text, "object tipped: its tracked axis leans %.1f deg after the nudge", hit.tilt_deg);
    end_attempt(Outcome::Tipped, text, now);
    return false;
  }
  const Eigen::Vector3d foot = scene_.right_to_world(hit.point);
  a.rest = Eigen::Vector3d(foot.x(), foot.y(), 0.0);
  return true;
}

// Without trackers: the settled AXES near the push line (upright, by the triangulation service).
// The window reaches along the camera's ray by the stereo depth error, so it can hold the pushed
// object's axes and another object's (or a phantom's) further along the ray. The axes are grouped
// by where they stand, and the group nearest the push line with enough axes is the object: a
// median over all of them would put the object between the two.
Supervisor::RestGroup Supervisor::rest_group() const {
  const Attempt& a = *attempt_;
  struct Near {
    const Axis* axis;
    double in_depth;
  };
  std::vector<Near> near;
  const Eigen::Vector2d ray = viewing_ray(a.target.position);
  for (const Axis& axis : settled_axes_) {
    const Eigen::Vector3d offset = axis.foot - a.target.position;
    const double along = offset.head<2>().dot(a.direction.head<2>());
    const Eigen::Vector2d across = offset.head<2>() - along * a.direction.head<2>();
    // Off the push line: along the camera's ray by the stereo depth error, sideways by little.
    const double in_depth = std::abs(across.dot(ray));
    const double sideways = (across - across.dot(ray) * ray).norm();
    if (along < -config_.max_lateral_m || along > config_.max_travel_m || sideways > config_.max_lateral_m ||
        in_depth > config_.max_lateral_m + config_.max_depth_error_m)
      continue;
    near.push_back({&axis, in_depth});
  }
  std::sort(near.begin(), near.end(), [](const Near& l, const Near& r) { return l.in_depth < r.in_depth; });
  // The object's group: the largest one standing on the push line itself; only when none does, the
  // nearest one off it in depth (a few stray axes on the line must not outvote the object's many).
  RestGroup rest;
  rest.near = static_cast<int>(near.size());
  for (const Near& seed : near) {
    std::vector<const Axis*> group;
    for (const Near& other : near)
      if ((other.axis->foot - seed.axis->foot).head<2>().norm() <= config_.same_axis_m) group.push_back(other.axis);
    if (static_cast<int>(group.size()) < config_.min_axes) continue;
    const bool on_line = seed.in_depth <= config_.max_lateral_m;
    if (rest.axes.empty() || (on_line && group.size() > rest.axes.size())) rest.axes = std::move(group);
    if (!on_line) break;
  }
  return rest;
}

namespace {

// The axes within `radius` and `max_tilt_difference` of the group's axis with the most such
// neighbours (of equals, the most upright, then the earliest); the whole group when that core has
// fewer than `min_axes`, or when `radius` is 0.
std::vector<const Axis*> repeating_core(const std::vector<const Axis*>& group, double radius, double max_tilt_difference,
                                        int min_axes) {
  if (radius <= 0) return group;
  std::vector<const Axis*> best;
  double best_tilt = 0;
  for (const Axis* seed : group) {
    std::vector<const Axis*> core;
    for (const Axis* other : group)
      if ((other->foot - seed->foot).head<2>().norm() <= radius && std::abs(other->tilt_rad - seed->tilt_rad) <= max_tilt_difference)
        core.push_back(other);
    if (core.size() > best.size() || (core.size() == best.size() && seed->tilt_rad < best_tilt)) {
      best = std::move(core);
      best_tilt = seed->tilt_rad;
    }
  }
  return static_cast<int>(best.size()) >= min_axes ? best : group;
}

}  // namespace

bool Supervisor::verify_by_axes(int64_t now) {
  Attempt& a = *attempt_;
  const RestGroup rest = rest_group();
  std::vector<double> xs, ys, tilts;
  const double core_tilt = config_.rest_core_tilt_deg * M_PI / 180;
  for (const Axis* axis : repeating_core(rest.axes, config_.rest_core_m, core_tilt, config_.min_axes)) {
    xs.push_back(axis->foot.x());
    ys.push_back(axis->foot.y());
    tilts.push_back(axis->tilt_rad);
  }
  if (static_cast<int>(xs.size()) < config_.min_axes) {
    const std::string settled =
        std::to_string(xs.size()) + " upright axes in one place near the push line after " +
        seconds_text(std::round(std::max<double>(0, latest_axes_utime_ - arm_done_time_) / 1e5) / 10) +
        " of settling (" + std::to_string(rest.near) + " near it)";
    if (rest_from_still_allowed()) {
      // Placed by the after still's line (segment()); until then, where the push would take it.
      a.rest_from_still = true;
      a.settle_note = settled;
      a.rest = a.target.position + config_.push_travel_m * a.direction;
      return true;
    }
    end_attempt(Outcome::Tipped, "object tipped or lost: " + settled, now);
    return false;
  }
  const double tilt_deg = median(tilts) * 180 / M_PI;
  a.rest_tilt_deg = tilt_deg;
  if (tilt_deg > config_.upright_max_tilt_deg) {
    char text[96];
    std::snprintf(text, sizeof text, "object tipped: its axis leans %.1f deg after the nudge", tilt_deg);
    end_attempt(Outcome::Tipped, text, now);
    return false;
  }
  a.rest = Eigen::Vector3d(median(xs), median(ys), 0.0);
  return true;
}

void Supervisor::segment(int64_t now) {
  const auto started = std::chrono::steady_clock::now();
  const double started_cpu_ms = thread_cpu_ms();
  Attempt& a = *attempt_;
  // The CPU time of each stage of the plan on this thread (attempt.json: grasp_plan_stages_ms).
  std::vector<std::pair<std::string, double>> stages;
  double lap_start_ms = started_cpu_ms;
  const auto lap = [&](const char* stage) {
    const double at = thread_cpu_ms();
    stages.emplace_back(stage, at - lap_start_ms);
    lap_start_ms = at;
  };
  enter(State::Segment, now, "motion segmentation of the stills");
  const auto predicted_before = scene_.right_axis_line(a.target.position, config_.object_height_m, config_.still_size);
  const std::vector<symmetry::Line> column = base_column_lines(1);
  if (predicted_before && a.rest_from_still && !place_by_after_still(a, *predicted_before, column)) {
    end_attempt(Outcome::Tipped, "object tipped or lost: " + a.settle_note +
                                     ", and no new upright line along the push in the after still", now);
    return;
  }
  if (predicted_before && !a.rest_from_still && far_rest_where_nothing_changed(a))
    axes_rest_gives_way_to_after_still(a, *predicted_before, column);
  const auto predicted_after = scene_.right_axis_line(*a.rest, config_.object_height_m, config_.still_size);
  if (!predicted_before || !predicted_after) {
    end_attempt(Outcome::SegmentationFailed, "the object left the right camera's view", now);
    return;
  }
  // Learning: the left camera's segmentation (for the object's top) alongside the right one's, on
  // the second core when the shell gave it its own segmenter (the grasp is planned sooner).
  std::future<void> left;
  // The left camera's task writes into `a`: waited for however this function is left (a worker's
  // future, unlike std::async's, does not wait when destroyed).
  const WaitOnExit left_joined{left};
  if (a.learn) {
    auto task = [this, &a, rest = *a.rest] { segment_left(a, rest); };
    left = left_worker_ ? left_worker_->run(task) : std::async(std::launch::deferred, task);
  }
  // The object's own lines in the stills; the calibration's prediction where none is detected.
  // (The before still's line was searched for while the arm nudged: see before_lines.)
  lap("right rest from the still");
  if (!a.before_line) a.before_line = find_line_near(a.before, *predicted_before, config_.line_search, column);
  lap("right before line");
  if (!a.rest_from_still) {
    a.after_line = find_moved_line(a.after, *predicted_after, *predicted_before, a.before_line, config_.line_search, column);
    if (const auto pushed = line_along_the_push(a, *predicted_before, column)) a.after_line = pushed;
    if (look_past_a_weak_after_line(a, *predicted_before, column) && left.valid()) {
      left.get();  // the left camera's segmentation was about the old rest: again about the new
      left = std::async(std::launch::deferred, [this, &a, rest = *a.rest] { segment_left(a, rest); });
    }
  }
  if (!a.before_line) a.before_line = predicted_before;
  if (!a.after_line) a.after_line = predicted_after;
  lap("right after line");
  const bool stages_later = a.learn && segment_stageless_;
  a.segmentation = (stages_later ? segment_stageless_ : segment_)(a.before, a.after, *a.before_line, *a.after_line);
  lap("right segmentation");
  keep_object_rows(a);
  keep_object_columns(a);
  lap("right mask's neighbours cleared");
  if (left.valid()) {
    const Stopwatch waited;
    left.get();  // joined before the attempt can end
    stages.emplace_back("wait for the left camera (wall)", waited.elapsed_ms());
    lap_start_ms = thread_cpu_ms();  // a deferred left ran on this thread: counted as its own stages
  }
  // Fig. 6.7's stages for the attempt's files when the segmentation went without them: drawn
  // after the grasp is planned, off its clock (an attempt that ended meanwhile waits in outputs_,
  // not yet written, and `a` is still it).
  auto draw_stages = [&] {
    if (stages_later) a.segmentation.stages = segment_(a.before, a.after, *a.before_line, *a.after_line).stages;
  };
  const int mask_pixels = a.segmentation.mask.empty() ? 0 : cv::countNonZero(a.segmentation.mask);
  if (mask_pixels < config_.min_mask_pixels) {
    draw_stages();
    end_attempt(Outcome::SegmentationFailed,
                "segmentation empty" + (a.segmentation.error.empty() ? std::string() : ": " + a.segmentation.error), now);
    return;
  }
  const std::string not_an_object = mask_shape_problem(a.segmentation.mask, a.after, *a.rest, *a.after_line);
  if (!not_an_object.empty()) {
    draw_stages();
    end_attempt(Outcome::SegmentationFailed, not_an_object, now);
    return;
  }
  // The right mask read once: the object's top for the grasp, its foot for the rest's check.
  const std::optional<MaskOnLine> right_mask = read_mask_on_line(a.segmentation.mask, *a.after_line);
  if (right_mask) a.top[1] = right_mask->top;
  check_rest_with_mask(a, right_mask);
  if (const std::string fell = fallen_over(a); !fell.empty()) {
    draw_stages();
    end_attempt(Outcome::Tipped, fell, now);
    return;
  }
  if (a.learn) {
    lap("right mask checks");
    plan_grasp(now);
    if (state_ == State::Grasp) {
      lap("grasp and arm plan");
      a.grasp_plan_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started).count();
      a.grasp_plan_cpu_ms = thread_cpu_ms() - started_cpu_ms;
      stages.insert(stages.end(), a.left_stages_cpu_ms.begin(), a.left_stages_cpu_ms.end());
      a.grasp_plan_stages_ms = std::move(stages);
    }
    draw_stages();
    return;
  }
  end_attempt(Outcome::Segmented, "segmented", now);
}

// A push runs across the right camera's view, so the pushed object's line moves in the right
// still. An after line found where the before line stood, when the rest has not come along the
// push either but lies off the push line in depth (a stereo mismatch), is something that
// stood still: a line in line with the object (the first held-out set's h09: the water bottle
// stood in line with the arm's base column, whose line paired with the bottle's left one into
// settled axes 5 cm off in depth; the after line was predicted and found on the column's, and the
// mask was the bottle where it had stood). The object is then looked for where the push took it
// (config_.push_travel_m along the push), passing over the standing line. Nothing when the after
// line moved, the rest came along the push, or nothing is found there.
std::optional<symmetry::Line> Supervisor::line_along_the_push(const Attempt& a, const symmetry::Line& predicted_before,
                                                              const std::vector<symmetry::Line>& column) const {
  if (config_.push_travel_m <= 0 || !a.after_line || !a.before_line || !a.rest) return std::nullopt;
  const Eigen::Vector2d moved = (*a.rest - a.target.position).head<2>();
  const double along = moved.dot(a.direction.head<2>());
  const double in_depth = std::abs((moved - along * a.direction.head<2>()).dot(viewing_ray(a.target.position)));
  const double max_angle = config_.line_search.not_object_deg * M_PI / 180;
  // An object that barely slid along the push line keeps its line: only a rest off the line in
  // depth (the settled axes' mismatch) says nothing about where the object went.
  if (along >= config_.standing_line_max_travel_m || in_depth <= config_.max_lateral_m ||
      !lines_agree(*a.after_line, *a.before_line, max_angle, config_.line_search.not_object_px))
    return std::nullopt;
  const auto predicted = scene_.right_axis_line(a.target.position + config_.push_travel_m * a.direction,
                                                config_.object_height_m, config_.still_size);
  if (!predicted) return std::nullopt;
  std::vector<symmetry::Line> standing = column;
  standing.push_back(*a.after_line);
  return find_moved_line(a.after, *predicted, predicted_before, a.before_line, config_.line_search, standing);
}

// The after still may place an object the settled axes did not (Config::rest_from_still) only
// when the pipeline delivered the settled frames' axes: without them (a stalled pipeline) nothing
// says the object is not simply unseen by a dead service, and the attempt ends as before.
bool Supervisor::rest_from_still_allowed() const {
  const int64_t settled = arm_done_time_ + static_cast<int64_t>(config_.settle_s * kMicro);
  return config_.rest_from_still && config_.push_travel_m >= config_.min_displacement_m && !trackers_decide() &&
         latest_axes_utime_ >= settled;
}

// Config::far_rest_m: the settled axes' rest lies far along the push, and nothing changed about
// its projected line between the stills.
bool Supervisor::far_rest_where_nothing_changed(const Attempt& a) const {
  if (!config_.rest_from_still || config_.far_rest_m <= 0 || !a.rest || a.before.empty() || a.after.empty()) return false;
  if ((*a.rest - a.target.position).head<2>().dot(a.direction.head<2>()) <= config_.far_rest_m) return false;
  const auto line = scene_.right_axis_line(*a.rest, config_.object_height_m, config_.still_size);
  if (!line) return false;
  const double half_width = 0.5 * config_.line_search.min_pair_width_px * a.after.cols / 640.0;
  return changed_share(a.before, a.after, *line, half_width, config_.line_search.change_threshold) <
         config_.line_search.min_changed_share;
}

// Config::rest_from_still: the object's line in the right after still, a new upright line along
// the push. A line about which nothing changed since the before still stood there before the push
// and is passed over (the object's own line when it did not move, a neighbour standing along the
// push, the arm's base column; LineSearchParams::min_changed_share). Sets the attempt's after line
// and its rest (the point of the push line whose upright axis projects nearest the line); false
// when no such line is found.
bool Supervisor::place_by_after_still(Attempt& a, const symmetry::Line& predicted_before,
                                      const std::vector<symmetry::Line>& column) const {
  const Eigen::Vector3d& from = a.target.position;
  const Eigen::Vector3d along = a.direction.normalized();
  const auto predicted = scene_.right_axis_line(from + config_.push_travel_m * along, config_.object_height_m, config_.still_size);
  if (!predicted || a.after.empty()) return false;
  const auto found = find_moved_line(a.after, *predicted, predicted_before, a.before_line, config_.line_search, column, a.before);
  if (!found) return false;
  double best_offset = config_.line_search.window_px, best_travel = 0;
  bool placed = false;
  for (double travel = -config_.max_lateral_m; travel <= config_.max_travel_m; travel += 0.001) {
    const auto line = scene_.right_axis_line(from + travel * along, config_.object_height_m, config_.still_size);
    if (!line) continue;
    const double offset = std::abs(symmetry::line_difference(*found, *line).r);
    if (offset < best_offset) best_offset = offset, best_travel = travel, placed = true;
  }
  if (!placed) return false;
  a.rest = from + best_travel * along;
  a.after_line = found;
  return true;
}

// Config::weak_after_line_share: the after line found about the settled axes' rest has few of the
// before line's votes; a stronger new line along the push (place_by_after_still) replaces it and
// its rest. True when it did.
bool Supervisor::look_past_a_weak_after_line(Attempt& a, const symmetry::Line& predicted_before,
                                             const std::vector<symmetry::Line>& column) const {
  if (config_.weak_after_line_share <= 0 || !config_.rest_from_still || !a.before_line || !a.after_line || !a.rest)
    return false;
  const double weak = a.after_line->votes;
  if (weak >= config_.weak_after_line_share * a.before_line->votes) return false;
  if (!axes_rest_gives_way_to_after_still(a, predicted_before, column, weak)) return false;
  a.weak_after_line_votes = weak;
  return true;
}

// The settled axes' rest replaced by the after still's new line along the push
// (place_by_after_still), when one is found with more than `more_votes_than` votes: the axes' rest
// kept as rest_from_axes. False, and the attempt as it was, otherwise.
bool Supervisor::axes_rest_gives_way_to_after_still(Attempt& a, const symmetry::Line& predicted_before,
                                                    const std::vector<symmetry::Line>& column,
                                                    double more_votes_than) const {
  const Eigen::Vector3d from_axes = *a.rest;
  const std::optional<symmetry::Line> line_before_search = a.after_line;
  if (!place_by_after_still(a, predicted_before, column)) return false;
  if (a.after_line->votes <= more_votes_than) {
    a.rest = from_axes;
    a.after_line = line_before_search;
    return false;
  }
  a.rest_from_axes = from_axes;
  a.rest_from_still = true;
  return true;
}

std::string Supervisor::mask_shape_problem(const cv::Mat& mask, const cv::Mat& still, const Eigen::Vector3d& rest,
                                           const symmetry::Line& line) const {
  const int pixels = cv::countNonZero(mask);
  const cv::Size2d smallest = smallest_object_image(rest);
  const double share = config_.min_mask_share;
  if (pixels < share * smallest.area())
    return "segmentation too small for an object: " + std::to_string(pixels) + " px, the smallest object there shows " +
           std::to_string(static_cast<int>(smallest.area())) + " px";
  const int rows = rows_with_pixels(mask);
  if (rows < share * smallest.height)
    return "segmentation too flat for an object: " + std::to_string(rows) + " rows, the smallest object there is " +
           std::to_string(static_cast<int>(smallest.height)) + " rows tall";
  const double mean_width = static_cast<double>(pixels) / rows;
  if (mean_width < share * smallest.width)
    return "segmentation too thin for an object: " + std::to_string(static_cast<int>(mean_width)) +
           " px wide on average, the smallest object there is " + std::to_string(static_cast<int>(smallest.width)) + " px wide";
  const double mirrored = segmentation::mirror_agreement(mask, line);
  if (mirrored < config_.min_mask_mirror_agreement) {
    char text[16];
    std::snprintf(text, sizeof text, "%.2f", mirrored);
    return std::string("segmentation not symmetric about the object's line: it agrees ") + text + " with its mirror image";
  }
  if (config_.min_mask_side_edges > 0 && still.size() == mask.size()) {
    const double on_edges = segmentation::side_edge_support(mask, still);
    if (on_edges < config_.min_mask_side_edges) {
      char text[160];
      std::snprintf(text, sizeof text,
                    "segmentation's sides leave the object's outline: one side lies on an edge of the still in only %.0f%% of its rows",
                    100 * on_edges);
      return text;
    }
  }
  return "";
}

// The smallest object expected standing at `foot` (world) in the right still: its width across the
// camera's view and its height, both projected.
cv::Size2d Supervisor::smallest_object_image(const Eigen::Vector3d& foot) const {
  const Eigen::Vector3d base(foot.x(), foot.y(), 0.0);
  const auto width = width_across_view_px(base, 2 * config_.min_object_radius_m, config_.still_size);
  const auto top = scene_.project_right(base + Eigen::Vector3d(0, 0, config_.min_object_height_m), config_.still_size);
  const auto bottom = scene_.project_right(base, config_.still_size);
  if (!width || !top || !bottom) return {0.0, 0.0};
  return {*width, cv::norm(*top - *bottom)};
}

// The right camera's image (of `size`) of `width_m` across its view, centred at `at` (world): px
// between the images of its two ends; nothing when either is out of the camera's sight.
std::optional<double> Supervisor::width_across_view_px(const Eigen::Vector3d& at, double width_m, cv::Size size) const {
  const Eigen::Vector2d ray = viewing_ray(at);
  const Eigen::Vector3d half = 0.5 * width_m * Eigen::Vector3d(-ray.y(), ray.x(), 0.0);
  const auto left = scene_.project_right(at - half, size);
  const auto right = scene_.project_right(at + half, size);
  if (!left || !right) return std::nullopt;
  return cv::norm(*left - *right);
}

// The settled axes' rest against the mask's foot (after the left segmentation has joined: it
// reads the rest).
void Supervisor::check_rest_with_mask(Attempt& a, const std::optional<MaskOnLine>& right_mask) const {
  if (right_mask) a.rest_from_mask = foot_from_mask(scene_, *right_mask);
  if (right_mask && a.rest) a.mask_front_hidden_behind = known_object_hiding_base(*right_mask, *a.rest);
  if (!a.rest_from_mask || !a.rest || config_.rest_mask_disagreement_m <= 0 || a.mask_front_hidden_behind) return;
  const double apart = (*a.rest_from_mask - *a.rest).head<2>().norm();
  if (apart <= config_.rest_mask_disagreement_m || apart > config_.max_lateral_m + config_.max_depth_error_m) return;
  a.rest_from_axes = a.rest;
  a.rest = a.rest_from_mask;
}

// A known object standing in front of the base hides it: the mask ends at its outline. Its place
// is known to a couple of centimetres (a rest, or where it was put back), and the line may run
// along its edge (the demo's bottle behind the mug), so it is taken that much wider.
std::optional<Eigen::Vector3d> Supervisor::known_object_hiding_base(const MaskOnLine& right_mask,
                                                                    const Eigen::Vector3d& rest) const {
  constexpr double kPlaceUncertainty = 0.02;
  for (const ExploredObject& object : standing_) {
    if ((object.place - rest).head<2>().norm() < config_.targets.same_object_radius) continue;  // the object itself
    const double height = object.height > 0 ? object.height : config_.targets.obstacle_height;
    if (mask_front_hidden_by(scene_, right_mask, rest, object.place, config_.targets.object_radius + kPlaceUncertainty, height))
      return object.place;
  }
  return std::nullopt;
}

// Config::doubtful_tilt_deg: the settled axes lean enough to doubt that they are the pushed
// object's, and its mask shows no upright object's base, nor one a known object in front hides
// of a target the survey counted as an object. Why the attempt is "tipped or lost", or empty.
std::string Supervisor::fallen_over(const Attempt& a) const {
  if (config_.doubtful_tilt_deg <= 0 || !a.rest_tilt_deg || *a.rest_tilt_deg <= config_.doubtful_tilt_deg) return "";
  // A base the mask shows vouches for the lean. With the front hidden, the foot read from the mask
  // is the hider's outline, not a base: only a target the survey counted as an object is believed.
  if (a.mask_front_hidden_behind ? a.target.stereo_agreement >= config_.targets.min_stereo_agreement : a.rest_from_mask.has_value())
    return "";
  char text[256];
  if (a.mask_front_hidden_behind)
    std::snprintf(text, sizeof text,
                  "object tipped or lost: its settled axes lean %.1f deg, its mask's base is hidden by the known object at %s, "
                  "and the survey saw the target in only %.0f%% of its stereo pairs",
                  *a.rest_tilt_deg, millimetres(*a.mask_front_hidden_behind).c_str(), 100 * a.target.stereo_agreement);
  else
    std::snprintf(text, sizeof text,
                  "object tipped or lost: its settled axes lean %.1f deg and its mask shows no upright object's base", *a.rest_tilt_deg);
  return text;
}

// Only rows between the object's foot and the tallest object's top can be the object: motion
// further up the line (an arm, a hand) is not kept.
void Supervisor::keep_object_rows(Attempt& a) const {
  cv::Mat& mask = a.segmentation.mask;
  if (mask.empty() || !a.rest) return;
  // The rest may be off by the stereo depth error along the camera's ray: the rows of the object
  // standing anywhere in that range (nearer: its foot lower in the image).
  const Eigen::Vector2d ray = viewing_ray(*a.rest);
  const Eigen::Vector3d depth = config_.max_depth_error_m * Eigen::Vector3d(ray.x(), ray.y(), 0);
  const Eigen::Vector3d up(0, 0, config_.object_height_m);
  double lowest = -1e9, highest = 1e9;
  for (const Eigen::Vector3d& foot_at : {Eigen::Vector3d(*a.rest - depth), Eigen::Vector3d(*a.rest + depth)}) {
    const auto foot = scene_.project_right(foot_at, mask.size());
    const auto top = scene_.project_right(foot_at + up, mask.size());
    if (!foot || !top) return;
    lowest = std::max({lowest, foot->y, top->y});
    highest = std::min({highest, foot->y, top->y});
  }
  const int margin = mask.rows / 48;  // 20 px at 960 rows: the foot's shadow and rounding
  const int first = std::clamp(static_cast<int>(highest) - margin, 0, mask.rows);
  const int last = std::clamp(static_cast<int>(lowest) + margin, 0, mask.rows);
  mask.rowRange(0, first).setTo(0);
  mask.rowRange(last, mask.rows).setTo(0);
}

// Only pixels within the widest object's half-width of the after line can be the object: a
// neighbour that moved with it, attached to the mask as a rigid part, is not kept.
void Supervisor::keep_object_columns(Attempt& a) const {
  cv::Mat& mask = a.segmentation.mask;
  if (mask.empty() || !a.rest || !a.after_line || config_.max_object_half_width_m <= 0) return;
  // The rest may be nearer the camera by the stereo depth error: the object's image is widest there.
  const Eigen::Vector2d ray = viewing_ray(*a.rest);
  const Eigen::Vector3d foot = *a.rest - config_.max_depth_error_m * Eigen::Vector3d(ray.x(), ray.y(), 0);
  const auto widest = width_across_view_px(foot, 2 * config_.max_object_half_width_m, mask.size());
  if (!widest) return;
  const int margin = mask.cols / 128;  // 10 px at 1280 columns: the line's error, rounding
  a.mask_pixels_beside = segmentation::keep_near_line(mask, *a.after_line, 0.5 * *widest + margin);
}

void Supervisor::end_attempt(Outcome outcome, const std::string& reason, int64_t now) {
  Attempt& a = *attempt_;
  a.outcome = outcome;
  a.reason = reason;
  a.ended = now;
  ++summary_.outcomes[to_string(outcome)];
  if (outcome == Outcome::Segmented) ++summary_.segmented;
  if (outcome == Outcome::Known) summary_.known.push_back(a.recognised);
  // A place once nudged is not nudged again (unless the attempt never touched it).
  if (outcome == Outcome::NoMotion) {
    // The target was a phantom, an axis between two objects (or something that would not move):
    // its neighbours and what stands on its lines in a camera are those objects, still to nudge.
    phantoms_.push_back(a.target.position);
    if (a.rest) phantoms_.push_back(*a.rest);
    else empty_.push_back(a.target.position);
  } else if (outcome != Outcome::Aborted && outcome != Outcome::SnapshotLost) {
    if (!retry_from_rest(a)) {
      explored_.push_back(a.target.position);
      for (const Candidate& c : a.candidates)  // the same object seen at another depth
        if ((c.position - a.target.position).head<2>().norm() < config_.targets.same_object_radius) explored_.push_back(c.position);
      if (a.rest) explored_.push_back(*a.rest);
    }
    if (a.rest && outcome == Outcome::Segmented) {
      // Only a segmented object is known to stand at its rest. Another outcome's rest may be the
      // phantom's axes seen again after a push that barely moved a neighbour; leaving its lines
      // out of the surveys would leave out the neighbours' lines that made it (development m03:
      // the yellow cup was never a candidate again).
      // Put back after learning, it stands where the arm put it, and its mask shows it no more.
      const Eigen::Vector3d place = a.put_back_at.value_or(*a.rest);
      const cv::Mat mask = a.put_back_at ? cv::Mat() : a.segmentation.mask;
      rested_.push_back({place, mask, mask.empty() ? cv::Rect() : cv::boundingRect(mask)});
      if (a.put_back_at) explored_.push_back(place);
      a.standing_height = explored_object_height(a);
      standing_.push_back({place, a.standing_height});
    } else if (outcome == Outcome::Known || outcome == Outcome::Refused) {
      a.standing_height = explored_object_height(a);
      standing_.push_back({a.target.position, a.standing_height});  // never pushed: it stands where it was found
    }
  }
  if (outcome == Outcome::SnapshotLost && a.before.empty()) {
    // A still lost to a busy camera or the network says nothing about the candidate: it is tried
    // once more. Lost again, it is passed over (a camera that never answers must not loop the run).
    if (near_any(a.target.position, still_lost_, config_.targets.same_object_radius)) explored_.push_back(a.target.position);
    else still_lost_.push_back(a.target.position);
  }
  outputs_.push_back(AttemptEnded{std::shared_ptr<const Attempt>(attempt_.release())});
  watch_.reset();
  for (auto& tracker : trackers_) tracker.reset();
  tracking_started_ = false;
  clear_settled_axes();
  const std::string why = "attempt " + std::to_string(a.number) + " " + to_string(outcome) + ": " + reason;
  learn_seq_ = 0;
  if (nudge_seq_ == 0 && !arm_away_) {
    survey(now, why);
    return;
  }
  // The arm has moved: park it before looking again.
  nudge_seq_ = 0;
  park(now, why + "; parking the arm");
}

// Whether a failed segmentation's object is to be nudged again: it moved, so it stands near its
// rest (a push of a few cm leaves it within same_object_radius of where it was, so neither place
// is explored), and it has failed fewer than segmentation_retries times. The failures are counted
// at both places, so a rest estimated in the wrong place cannot restart the count.
bool Supervisor::retry_from_rest(Attempt& a) {
  if (a.outcome != Outcome::SegmentationFailed || !a.rest) return false;
  if (target_line_stood_still(a)) {
    a.reason += "; its line stood still in the stills: not nudged again";
    return false;
  }
  int failures = 1;
  for (const auto& [place, count] : retries_)
    if ((place - a.target.position).head<2>().norm() < config_.targets.same_object_radius)
      failures = std::max(failures, count + 1);
  if (failures > config_.segmentation_retries) return false;
  retries_.emplace_back(a.target.position, failures);
  retries_.emplace_back(*a.rest, failures);
  a.reason += "; its rest will be nudged again";
  return true;
}

// An empty segmentation whose before and after lines are one line (Config::retry_still_line_px).
bool Supervisor::target_line_stood_still(const Attempt& a) const {
  if (config_.retry_still_line_px <= 0 || !a.before_line || !a.after_line) return false;
  const bool empty = a.segmentation.mask.empty() || cv::countNonZero(a.segmentation.mask) < config_.min_mask_pixels;
  return empty && lines_agree(*a.after_line, *a.before_line, M_PI / 180, config_.retry_still_line_px);
}

int64_t Supervisor::awaited_arm_seq() const {
  if (state_ == State::Nudge) return nudge_seq_;
  if (state_ == State::Home) return home_seq_;
  if (state_ == State::Grasp || state_ == State::Place || (state_ == State::Rotate && learn_seq_ != 0)) return learn_seq_;
  return 0;
}

// ---- inputs ----

void Supervisor::on_clock_restart(int64_t now) {
  entered_ = now;
  request_time_ = std::min(request_time_, now);
  arm_done_time_ = std::min(arm_done_time_, now);
  still_asked_ = std::min(still_asked_, now);
}

void Supervisor::on_time(int64_t now) {
  switch (state_) {
    case State::WaitServices:
      if (timed_out(config_.services_timeout_s, now)) {
        std::string names;
        for (const std::string& s : silent_) names += (names.empty() ? "" : ", ") + s;
        finish(State::Failed, "services never came up: " + names, now);
      }
      break;
    case State::FindCandidates:
      if (timed_out(config_.candidates_timeout_s, now))
        finish(State::Failed, "no CANDIDATES answer within " + std::to_string(static_cast<int>(config_.candidates_timeout_s)) + " s", now);
      break;
    case State::SnapshotBefore:
    case State::SnapshotAfter:
      if (!still_overdue(now)) break;
      // Learning without the left still: the attempt goes on as a segmentation only. Placing the
      // target anew without it: the survey's place is pushed.
      if (attempt_->learn && !(state_ == State::SnapshotBefore ? attempt_->before : attempt_->after).empty()) {
        attempt_->learn = false;
        attempt_->learning = "not grasped";
        attempt_->learning_reason = "the left still never came" + still_requests_text();
        stills_arrived(now);
      } else if (state_ == State::SnapshotBefore && !attempt_->before.empty()) {
        stills_arrived(now);
      } else {
        end_attempt(Outcome::SnapshotLost, std::string("the ") + (state_ == State::SnapshotBefore ? "before" : "after") + " still never came" + still_requests_text(), now);
      }
      break;
    case State::Nudge:
      if (timed_out(config_.nudge_timeout_s, now)) {
        outputs_.push_back(StopCommand{next_seq_++, "nudge timed out"});
        end_attempt(Outcome::ArmFailed, "the arm did not finish the nudge within " + std::to_string(static_cast<int>(config_.nudge_timeout_s)) + " s", now);
      }
      break;
    case State::Track:
      if (static_cast<double>(now - arm_done_time_) >= config_.settle_s * kMicro && axes_caught_up(now) &&
          !settling_longer(now))
        verify(now);
      break;
    case State::Home:
      if (timed_out(config_.nudge_timeout_s, now)) parked(now, "the arm did not report parking in time");
      break;
    case State::Recognise:
      if (timed_out(config_.recognise_timeout_s, now)) {
        attempt_->recognition_reason = "learner silent: no RECOGNITION within " + seconds_text(config_.recognise_timeout_s);
        start_nudge(now);
      }
      break;
    case State::Learn: {
      // The learner learns on a worker thread and says so in its heartbeat: the wait goes on while
      // it does, up to learn_max_wait_s; learn_timeout_s counts from the last such heartbeat.
      const bool heard_busy = learner_busy_ > entered_;
      if (timed_out(config_.learn_max_wait_s, now))
        place(now, "learner too slow", "no LEARNED within " + seconds_text(config_.learn_max_wait_s) +
                                           " (--learn-max-wait) though its heartbeat said it was learning " +
                                           attempt_->object_key() + " (the views are in the attempt's folder)");
      else if (static_cast<double>(now - std::max(entered_, learner_busy_)) > config_.learn_timeout_s * kMicro)
        place(now, "learner silent", "no LEARNED within " + seconds_text(config_.learn_timeout_s) +
                                         (heard_busy ? " of its last heartbeat saying it was learning " + attempt_->object_key() : "") +
                                         " (the views are in the attempt's folder)");
      break;
    }
    case State::Rotate:
      if (learn_seq_ == 0 && still_overdue(now)) {
        place(now, "snapshot lost", "view " + std::to_string(attempt_->views.size() + 1) + "'s still never came" + still_requests_text());
        break;
      }
      [[fallthrough]];
    case State::Grasp:
    case State::Place:
      if (learn_seq_ != 0 && timed_out(config_.arm_timeout_s, now)) {
        outputs_.push_back(StopCommand{next_seq_++, std::string(to_string(state_)) + " timed out"});
        learning_ended("arm failed", std::string("the arm did not finish ") + to_string(state_) + " within " + seconds_text(config_.arm_timeout_s), now);
      }
      break;
    default:
      break;
  }
}

// AXES of the frames taken when the settling time ended have arrived (a lagging pipeline delivers
// them late), or the wait for them is over.
bool Supervisor::axes_caught_up(int64_t now) const {
  if (trackers_decide()) return true;  // not the axes
  const int64_t settled = arm_done_time_ + static_cast<int64_t>(config_.settle_s * kMicro);
  return latest_axes_utime_ >= settled ||
         static_cast<double>(now - arm_done_time_) >= (config_.settle_s + config_.max_axes_lag_s) * kMicro;
}

// Too few settled axes in one place yet, and the frames of the longest settling time not all seen:
// an object that rocks after the push, or one the detection finds only in some frames, may show
// no axis in the settling second (s12's mug on a checkered table: placed after 4.3 s). Judged by
// the frames' times, so a replay waits exactly as the run did.
bool Supervisor::settling_longer(int64_t now) const {
  // A phantom (no motion) is judged at once, and so is an object whose rest has been found.
  if (trackers_decide() || !watch_ || !watch_->moved() || rest_found_) return false;
  const int64_t longest = arm_done_time_ + static_cast<int64_t>(config_.max_settle_s * kMicro);
  return latest_axes_utime_ < longest &&
         static_cast<double>(now - arm_done_time_) < (config_.max_settle_s + config_.max_axes_lag_s) * kMicro;
}

void Supervisor::on_services(const std::set<std::string>& silent, int64_t now) {
  const bool was_silent = !silent_.empty();
  silent_ = silent;
  if (finished() || state_ == State::Idle) return;
  if (state_ == State::WaitServices) {
    if (silent_.empty()) survey(now);
    return;
  }
  std::string names;
  for (const std::string& s : silent_) names += (names.empty() ? "" : ", ") + s;
  if (!silent_.empty() && state_ != State::Paused) {
    // Stop first, then say why: the arm must not move while the loop cannot see.
    outputs_.push_back(StopCommand{next_seq_++, "service silent: " + names});
    paused_from_ = state_;
    enter(State::Paused, now, "paused: no heartbeat from " + names);
  } else if (silent_.empty() && was_silent && state_ == State::Paused) {
    if (in_attempt()) {
      watch_.reset();
      for (auto& tracker : trackers_) tracker.reset();
      tracking_started_ = false;
      clear_settled_axes();
      Attempt& a = *attempt_;
      const bool touched = paused_from_ != State::SnapshotBefore && paused_from_ != State::Recognise;
      end_attempt(touched ? Outcome::Aborted : Outcome::SnapshotLost,
                  std::string("aborted: a service went silent during ") + to_string(paused_from_), now);
      (void)a;
    } else {
      survey(now);
    }
  }
}

void Supervisor::on_candidates(const std::vector<Candidate>& candidates, int64_t utime, int64_t now) {
  if (state_ != State::FindCandidates) return;
  if (utime < request_time_) return;  // an answer to an older request (or another run's)
  candidates_ = candidates;
  std::string where;
  for (Candidate& c : candidates_) {
    c.stereo_agreement = stereo_agreement(c);
    char agreement[32];
    std::snprintf(agreement, sizeof agreement, " (seen %.0f%%)", 100 * c.stereo_agreement);
    where += (where.empty() ? " at " : ", ") + millimetres(c.position) + agreement;
  }
  sighted_ = places_seen_by_right_lines();  // the survey's lines are complete: found once, for every choice
  std::string sighted;  // Config::line_obstacle_share: where the right camera's lines stand
  for (const Eigen::Vector3d& place : sighted_)
    sighted += (sighted.empty() ? "; the right camera's lines stand at " : ", ") + millimetres(place);
  enter(State::Choose, now, std::to_string(candidates.size()) + " candidates" + where + sighted);
  choose(now);
}

void Supervisor::on_arm_state(const ArmStatus& arm, int64_t now) {
  joints_ = arm.joints;
  if (state_ == State::Home && arm.command_seq == home_seq_ && arm.motion != ArmStatus::Motion::Moving &&
      arm.motion != ArmStatus::Motion::Idle) {
    // Parked, or not (refused, stopped): the loop goes on either way, saying so.
    parked(now, arm.motion == ArmStatus::Motion::Done ? "" : "the arm did not park (" + arm.last_error + ")");
    return;
  }
  if ((state_ == State::Grasp || state_ == State::Rotate || state_ == State::Place) && learn_seq_ != 0 &&
      arm.command_seq == learn_seq_) {
    on_learning_arm_state(arm, now);
    return;
  }
  if (state_ != State::Nudge || arm.command_seq != nudge_seq_) return;  // not about our nudge
  switch (arm.motion) {
    case ArmStatus::Motion::Refused:
      nudge_seq_ = 0;  // nothing moved: no need to park
      end_attempt(Outcome::Refused, "arm refused the nudge: " + arm.last_error, now);
      break;
    case ArmStatus::Motion::Stopped:
      end_attempt(Outcome::ArmFailed, "arm stopped during the nudge: " + arm.last_error, now);
      break;
    case ArmStatus::Motion::Done:
      arm_done_time_ = now;
      clear_settled_axes();
      latest_axes_utime_ = 0;
      enter(State::Track, now, "nudge done: waiting for the object to settle");
      break;
    default:
      break;
  }
}

void Supervisor::feed_tracker(int camera, const cv::Mat& frame, int64_t utime) {
  if (!trackers_[camera] || track_done_[camera] || (state_ != State::Nudge && state_ != State::Track)) return;
  const tracking::TrackState state = trackers_[camera]->feed(frame, utime);
  if (tracking_started_ && attempt_)
    attempt_->track_trace[camera].push_back({utime, static_cast<int>(state.status), state.line.r, state.line.theta,
                                             state.measurement_used, state.holding});
  if (state.status == tracking::TrackStatus::Tracking && state.has_estimate) {
    last_track_[camera] = state;
  } else if (tracking_started_ && state.status != tracking::TrackStatus::Tracking) {
    // A track that ends while it holds a still object has done its work (the object came to rest:
    // thesis sec. 6.3.2, "tracking stops after the nudge ... the object ceases all motion"); one
    // that ends while the object moved lost it.
    track_done_[camera] = true;
    if (!last_track_[camera].holding) track_lost_[camera] = state.reason.empty() ? "track ended" : state.reason;
  }
}

// Frames of the nudge count however late they arrive (a lagging camera stream delivers the end
// of the push after the arm reported done).
bool Supervisor::frame_of_the_nudge(int64_t utime) const {
  return state_ == State::Nudge || (state_ == State::Track && utime <= arm_done_time_);
}

void Supervisor::on_right_frame(const cv::Mat& frame, int64_t utime) {
  if (frame_of_the_nudge(utime) && watch_) {
    watch_->feed(frame);
    // Motion at the target starts the trackers, at the target's line in each camera.
    if (watch_->moved() && !tracking_started_ && trackers_[0] && trackers_[1]) {
      tracking_started_ = true;
      attempt_->tracking_started = utime;
      for (int camera = 0; camera < 2; ++camera) trackers_[camera]->start_at(*target_lines_[camera]);
    }
  }
  feed_tracker(1, frame, utime);
}

bool Supervisor::wants_frame(bool left) const {
  const int camera = left ? 0 : 1;
  const bool tracking = trackers_[camera] && !track_done_[camera] && (state_ == State::Nudge || state_ == State::Track);
  return tracking || (!left && (state_ == State::Nudge || state_ == State::Track) && watch_);
}

void Supervisor::on_left_frame(const cv::Mat& frame, int64_t utime) { feed_tracker(0, frame, utime); }

void Supervisor::on_right_still(const cv::Mat& still, int64_t utime, int64_t now) {
  if (utime < request_time_) return;  // taken before we asked
  if (still.size() != config_.still_size)
    throw std::invalid_argument("right still of " + std::to_string(still.cols) + "x" + std::to_string(still.rows) +
                                ", expected " + std::to_string(config_.still_size.width) + "x" + std::to_string(config_.still_size.height));
  if (state_ == State::SnapshotBefore || state_ == State::SnapshotAfter) {
    cv::Mat& kept = state_ == State::SnapshotBefore ? attempt_->before : attempt_->after;
    if (!kept.empty()) return;  // a second answer to the same request
    kept = still.clone();
    (state_ == State::SnapshotAfter ? attempt_->after_utime : attempt_->before_utime) = utime;
    if (stills_complete()) stills_arrived(now);
  } else if (state_ == State::Rotate && learn_seq_ == 0) {
    take_view(still, utime, now);
  }
}

void Supervisor::on_lines(bool left, const std::vector<symmetry::Line>& lines, int64_t utime, int64_t now) {
  (void)now;
  if (state_ != State::FindCandidates) return;
  if (utime < request_time_) return;  // a frame from before the survey, delivered late
  auto& kept = survey_lines_[left ? 0 : 1];
  kept.push_back(lines);
  if (kept.size() > 50) kept.erase(kept.begin());
}

// The object where the attempt left it, in the still that shows it there (a segmented object in
// the after still at its rest; one never pushed, known or refused, in the before still where it
// stands), with the margin: the top of the edge pairs symmetric about its line
// (measure_object_height), which errs high (symmetric clutter above an object raises it: 0.27-0.29
// m for a cup and a bottle before a cluttered wall, development m02), so it may lower the tallest
// expected but not raise it; and the top of its mask, which may (a mask cut short errs low, and is
// never trusted alone). 0 when the edge pairs give no height: the tallest expected is assumed.
double Supervisor::explored_object_height(Attempt& a) const {
  const bool moved = a.outcome == Outcome::Segmented && a.rest;
  const cv::Mat& still = moved ? a.after : a.before;
  const std::optional<symmetry::Line>& line = moved ? a.after_line : a.before_line;
  const Eigen::Vector3d foot = moved ? *a.rest : a.target.position;
  std::optional<double> edges = moved ? std::nullopt : a.measured_height;
  if (!edges && line && !still.empty()) edges = measure_object_height(scene_, still, *line, foot, config_.height);
  if (edges && std::isfinite(*edges) && *edges > 0) a.height_from_edges = edges;
  if (moved && a.top[1])
    if (const auto top = ray_height_over(scene_, foot, *a.top[1], still.size()); top && std::isfinite(*top) && *top > 0)
      a.height_from_mask = top;
  if (!a.height_from_edges) return 0;
  const double margin = config_.height.margin_m, tallest = config_.targets.obstacle_height;
  double height = tallest > 0 ? std::min(*a.height_from_edges + margin, tallest) : *a.height_from_edges + margin;
  if (a.height_from_mask) height = std::max(height, *a.height_from_mask + margin);
  return height;
}

History Supervisor::history() const {
  return History{explored_with_ray_mates(), phantoms_, empty_, standing_, sighted_};
}

std::vector<Eigen::Vector3d> Supervisor::places_seen_by_right_lines() const {
  const auto& messages = survey_lines_[1];
  if (config_.line_obstacle_share <= 0 || messages.empty()) return {};
  struct Place {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int lines = 0, frames = 0, last_frame = -1;
    Eigen::Vector3d mean() const { return sum / lines; }
  };
  std::vector<Place> places;
  const Eigen::Vector3d camera = scene_.right_camera_in_world();
  for (int frame = 0; frame < static_cast<int>(messages.size()); ++frame) {
    for (const symmetry::Line& line : messages[frame]) {
      const auto front = table_point_under_line_foot(scene_, line, config_.frame_size);
      if (!front) continue;
      const Eigen::Vector3d view = Eigen::Vector3d((*front - camera).x(), (*front - camera).y(), 0).normalized();
      const Eigen::Vector3d axis = *front + config_.foot_depth_typical_m * view;  // behind the base's front
      const double reach = arm_.point_to_base(axis).head<2>().norm();
      if (reach > config_.line_obstacle_reach_m || reach < config_.line_obstacle_inner_m) continue;
      auto near = std::find_if(places.begin(), places.end(), [&](const Place& p) {
        return (p.mean() - axis).head<2>().norm() < config_.targets.explored_radius;
      });
      if (near == places.end()) near = places.insert(places.end(), Place{});
      near->sum += axis;
      ++near->lines;
      if (near->last_frame != frame) ++near->frames, near->last_frame = frame;
    }
  }
  std::vector<Eigen::Vector3d> seen;
  for (const Place& p : places)
    if (p.frames >= config_.line_obstacle_share * static_cast<double>(messages.size())) seen.push_back(p.mean());
  return seen;
}

std::vector<symmetry::Line> Supervisor::agreement_lines(geometry::Side side, const std::vector<symmetry::Line>& lines) const {
  std::vector<symmetry::Line> kept;
  int unexplored = 0;
  for (const symmetry::Line& line : lines) {
    if (unexplored >= config_.agreement_lines) break;
    const bool explored = std::any_of(standing_.begin(), standing_.end(), [&](const ExploredObject& object) {
      return geometry::is_image_of_upright_axis(scene_.rig(), side, scene_.table(), line, scene_.world_to_right(object.place),
                                                config_.explored_line_px);
    });
    unexplored += !explored;
    kept.push_back(line);
  }
  return kept;
}

double Supervisor::stereo_agreement(const Candidate& candidate) const {
  // The second, wider look paired lines leaning up to wide_survey_tilt_deg: one of those agrees
  // with the candidate's predicted axis when it leans no more and passes within the offset of the
  // axis' middle (its R about the image centre moves with the lean, however close it passes).
  const double max_angle =
      (wide_survey_ ? std::max(config_.agreement_angle_deg, config_.wide_survey_tilt_deg) : config_.agreement_angle_deg) * M_PI / 180;
  auto agree = [&](const symmetry::Line& line, const symmetry::Line& predicted) {
    if (!wide_survey_) return lines_agree(line, predicted, max_angle, config_.agreement_offset_px);
    const cv::Point2d middle = 0.5 * (predicted.seg1 + predicted.seg2);
    return std::abs(symmetry::line_difference(line, predicted).theta) <= max_angle &&
           std::abs(signed_distance(line, middle, config_.frame_size)) <= config_.agreement_offset_px;
  };
  double agreement = 1.0;
  for (int camera = 0; camera < 2; ++camera) {
    const auto& messages = survey_lines_[camera];
    if (messages.empty()) continue;  // no lines heard: no evidence either way
    const auto predicted = camera == 0 ? scene_.left_axis_line(candidate.position, config_.object_height_m, config_.frame_size)
                                       : scene_.right_axis_line(candidate.position, config_.object_height_m, config_.frame_size);
    if (!predicted) return 0.0;
    const geometry::Side side = camera == 0 ? geometry::Side::Left : geometry::Side::Right;
    int seen = 0;
    for (const auto& lines : messages) {
      const std::vector<symmetry::Line> counted = agreement_lines(side, lines);
      seen += std::any_of(counted.begin(), counted.end(), [&](const symmetry::Line& line) { return agree(line, *predicted); });
    }
    agreement = std::min(agreement, static_cast<double>(seen) / messages.size());
  }
  return agreement;
}

void Supervisor::on_axes(const std::vector<Axis>& axes, int64_t utime, int64_t now) {
  (void)now;
  if (state_ != State::Track) return;
  // Judged by when the frames were taken, not when their axes arrived: a pipeline that lags
  // delivers, after the settling pause, axes of frames taken while the object still slid.
  latest_axes_utime_ = std::max(latest_axes_utime_, utime);
  if (static_cast<double>(utime - arm_done_time_) < config_.axes_from_s * kMicro) return;
  settled_axes_.insert(settled_axes_.end(), axes.begin(), axes.end());
  // Once per AXES message, not on every tick: the grouping is quadratic in the settled axes, and
  // once a group is large enough, more axes cannot take it away.
  if (!rest_found_) rest_found_ = static_cast<int>(rest_group().axes.size()) >= config_.min_axes;
}

void Supervisor::clear_settled_axes() {
  settled_axes_.clear();
  rest_found_ = false;
}

}  // namespace nudge::supervisor
