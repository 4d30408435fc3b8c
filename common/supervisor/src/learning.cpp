// The supervisor's learning states (thesis ch. 7, sec. 7.2): recognition before the nudge, and
// after a segmentation the grasp, the twelve turns in front of the right camera, the learner's
// commit and the object put back where it stood before the nudge.
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <future>
#include <utility>

#include "nudge/robot/command_planner.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/supervisor/line_search.hpp"
#include "nudge/supervisor/supervisor.hpp"
#include "nudge/timing.hpp"
#include "nudge/worker.hpp"

namespace nudge::supervisor {

namespace {

std::string mm(double metres) { return std::to_string(static_cast<int>(std::lround(metres * 1e3))) + " mm"; }

}  // namespace

std::string Attempt::object_key() const {
  char text[32];
  std::snprintf(text, sizeof text, "attempt_%02d", number);
  return text;
}

bool Supervisor::learning_enabled() const {
  return config_.learn == Config::Learn::On || (config_.learn == Config::Learn::Auto && learner_alive_);
}

bool Supervisor::stills_complete() const {
  const Attempt& a = *attempt_;
  if (state_ == State::SnapshotBefore)
    return !a.before.empty() && (!(a.learn || before_stills_of_both_cameras()) || !a.before_left.empty());
  return !a.after.empty() && (!a.learn || !a.after_left.empty());
}

void Supervisor::stills_arrived(int64_t now) {
  if (state_ == State::SnapshotAfter) {
    segment(now);
    return;
  }
  refine_target_by_stills();
  before_lines();
  prefer_rival_at_the_lines_foot();
  if (attempt_->learn) {
    recognise(now);
  } else {
    start_nudge(now);
  }
}

void Supervisor::on_left_still(const cv::Mat& still, int64_t utime, int64_t now) {
  if (!attempt_ || !(attempt_->learn || before_stills_of_both_cameras()) || utime < request_time_) return;
  if (state_ != State::SnapshotBefore && state_ != State::SnapshotAfter) return;
  if (still.size() != config_.still_size)
    throw std::invalid_argument("left still of " + std::to_string(still.cols) + "x" + std::to_string(still.rows) +
                                ", expected " + std::to_string(config_.still_size.width) + "x" + std::to_string(config_.still_size.height));
  cv::Mat& kept = state_ == State::SnapshotBefore ? attempt_->before_left : attempt_->after_left;
  if (!kept.empty()) return;
  kept = still.clone();
  if (stills_complete()) stills_arrived(now);
}

// The object's lines in the before stills, searched for before the nudge rather than after it:
// the time between the nudge's end and the grasp is the thesis' measure (160 ms).
void Supervisor::before_lines() {
  Attempt& a = *attempt_;
  if (const auto right = scene_.right_axis_line(a.target.position, config_.object_height_m, config_.still_size))
    a.before_line = find_line_near(a.before, *right, config_.line_search, base_column_lines(1));
  if (a.height_limit > 0 && a.before_line)
    a.measured_height = measure_object_height(scene_, a.before, *a.before_line, a.target.position, config_.height);
  if (!a.learn) return;
  if (const auto left = scene_.left_axis_line(a.target.position, config_.object_height_m, config_.still_size))
    a.before_line_left = find_line_near(a.before_left, *left, config_.line_search, base_column_lines(0));
}

// Sec. 7.3 before the nudge: a candidate the learner already knows is not learned twice.
void Supervisor::recognise(int64_t now) {
  const Attempt& a = *attempt_;
  const cv::Rect roi = cylinder_box(scene_, a.target.position, config_.targets.object_radius, 0.0,
                                    config_.object_height_m, config_.still_size);
  learn_seq_ = next_seq_++;
  enter(State::Recognise, now, "asking the learner whether candidate " + std::to_string(a.target.index) + " is known");
  outputs_.push_back(RecognizeRequest{learn_seq_, roi, a.before});
}

void Supervisor::on_recognition(int64_t seq, const std::string& label, const std::string& reason, int64_t now,
                                const cv::Mat& match_picture) {
  if (state_ != State::Recognise || seq != learn_seq_) return;
  learn_seq_ = 0;
  Attempt& a = *attempt_;
  a.recognition_match = match_picture.clone();
  if (!label.empty()) {
    a.recognised = label;
    end_attempt(Outcome::Known, "recognised as '" + label + "': already learned, not nudged", now);
    return;
  }
  a.recognition_reason = reason.empty() ? "not recognised" : reason;
  start_nudge(now);
}

// The left stills' lines and motion segmentation about the object's `rest` (possibly on another
// thread: it touches only the attempt's left fields and the left segmenter; the rest is the
// caller's copy, as the right still may yet move the attempt's).
void Supervisor::segment_left(Attempt& a, const Eigen::Vector3d& rest) const {
  const auto predicted_before = scene_.left_axis_line(a.target.position, config_.object_height_m, config_.still_size);
  const auto predicted_after = scene_.left_axis_line(rest, config_.object_height_m, config_.still_size);
  if (!predicted_before || !predicted_after) return;
  const std::vector<symmetry::Line> column = base_column_lines(0);
  const double started = thread_cpu_ms();
  if (!a.before_line_left) a.before_line_left = find_line_near(a.before_left, *predicted_before, config_.line_search, column);
  a.after_line_left =
      find_moved_line(a.after_left, *predicted_after, *predicted_before, a.before_line_left, config_.line_search, column);
  if (!a.before_line_left) a.before_line_left = predicted_before;
  if (!a.after_line_left) a.after_line_left = predicted_after;
  const double lines_done = thread_cpu_ms();
  const SegmentFunction& segment = segment_left_ ? segment_left_ : segment_;
  a.segmentation_left = segment(a.before_left, a.after_left, *a.before_line_left, *a.after_line_left);
  // Its own thread's CPU (attempt.json's grasp_plan_stages_ms); a second call replaces the first's.
  a.left_stages_cpu_ms = {{"left lines", lines_done - started}, {"left segmentation", thread_cpu_ms() - lines_done}};
}

void Supervisor::warm_up() const {
  const cv::Size size = config_.still_size;
  if (size.width < 64 || size.height < 64) return;
  // An object-sized block slid a fiftieth of the width between the stills, its axes vertical.
  cv::Mat before(size, CV_8UC3, cv::Scalar(90, 100, 110));
  cv::Mat after = before.clone();
  const int half_width = size.width / 20, shift = size.width / 50, top = size.height / 4, foot = 3 * size.height / 4;
  const auto axis = [&](int x) {
    symmetry::Line line;
    line.r = x - (size.width - 1) / 2.0;
    line.seg1 = cv::Point2d(x, foot);
    line.seg2 = cv::Point2d(x, top);
    symmetry::border_endpoints(line.r, line.theta, size.width, size.height, &line.end1, &line.end2);
    return line;
  };
  const int x = size.width / 2;
  cv::rectangle(before, cv::Rect(x - half_width, top, 2 * half_width, foot - top), cv::Scalar(40, 80, 200), cv::FILLED);
  cv::rectangle(after, cv::Rect(x + shift - half_width, top, 2 * half_width, foot - top), cv::Scalar(40, 80, 200), cv::FILLED);
  const symmetry::Line line_before = axis(x), line_after = axis(x + shift);
  const auto camera = [&](const SegmentFunction& segment) {
    find_line_near(after, line_after, config_.line_search);
    segment(before, after, line_before, line_after);
  };
  std::future<void> left;
  const WaitOnExit left_joined{left};  // it uses this function's stills
  if (left_worker_) left = left_worker_->run([&] { camera(segment_left_); });
  camera(segment_);
  if (segment_stageless_) segment_stageless_(before, after, line_before, line_after);
  if (left.valid()) left.get();
}

void Supervisor::set_left_segmentation(SegmentFunction segment) {
  segment_left_ = std::move(segment);
  if (!segment_left_) left_worker_.reset();
  else if (!left_worker_) left_worker_ = std::make_shared<Worker>();
}

// Sec. 7.2.2: the top in both cameras' segmentations, triangulated and lowered by r tan(theta);
// the grasp checked with the arm service's own planner before it is asked for.
void Supervisor::plan_grasp(int64_t now) {
  Attempt& a = *attempt_;
  if (!a.after_line_left) return learning_ended("not grasped", "the object is not in the left camera's view", now);
  a.top[0] = object_top(a.segmentation_left.mask, *a.after_line_left);  // a.top[1]: read in segment()
  for (int camera = 0; camera < 2; ++camera)
    if (!a.top[camera])
      return learning_ended("not grasped", std::string("no object top in the ") + (camera == 0 ? "left" : "right") +
                                               " segmentation" + (a.segmentation_left.error.empty() || camera == 1 ? "" : ": " + a.segmentation_left.error), now);
  a.grasp = grasp_target(scene_, *a.top[0], *a.top[1], config_.still_size, *a.rest, config_.grasp);
  if (!a.grasp->ok()) return learning_ended("not grasped", a.grasp->reason, now);
  a.expected_grip_width_m = object_width_at(scene_, a.segmentation.mask, a.grasp->foot, a.grasp->grasp_height_m);
  robot::Command grasp;
  grasp.kind = robot::CommandKind::Grasp;
  grasp.target_position = a.grasp->foot;
  grasp.height = a.grasp->grasp_height_m;
  const robot::MotionPlan plan = robot::plan_command(arm_.planner(), grasp, joints_);
  if (!plan.ok()) return learning_ended("not grasped", "the arm cannot grasp it: " + plan.reason, now);
  learn_seq_ = next_seq_++;
  arm_away_ = true;
  enter(State::Grasp, now, "grasping the object at " + millimetres(a.grasp->foot) + ", fingers " + mm(a.grasp->grasp_height_m) +
                               " above the table (top " + mm(a.grasp->top_height_m) + ": triangulated " + mm(a.grasp->top.z()) +
                               ", lowered " + mm(a.grasp->overestimate_m) + ")");
  outputs_.push_back(GraspCommand{learn_seq_, a.grasp->foot, a.grasp->grasp_height_m});
}

// A gripper that closed (nearly) fully holds nothing: the object slipped or was never caught.
// What a real robot knows (the fingers' opening), not the simulator's truth.
// Right after the grasp, fingers that closed to nearly nothing may still pinch a thin part (one
// finger inside a cup, the other outside its wall: the learning test's cup was carried off 9 cm
// above the table), so they open again where they closed, down at the grasp height. After a turn
// the object was held and has slipped out: there is nothing to put down.
bool Supervisor::holding(const ArmStatus& arm, const std::string& when, int64_t now) {
  if (state_ == State::Grasp) attempt_->grip_opening_m = arm.gripper_opening;
  if (arm.gripper_opening < 0) return true;
  if (arm.gripper_opening >= config_.held_min_opening_m) {
    if (state_ != State::Grasp) return true;
    const std::string off = grip_off_the_axis(arm.gripper_opening);
    if (off.empty()) return true;
    put_down(attempt_->grasp->foot, "the fingers open where they closed", now, "not grasped", off);
    return false;
  }
  const std::string reason = "nothing held " + when + ": the gripper closed to " + mm(arm.gripper_opening);
  if (state_ == State::Grasp)
    put_down(attempt_->grasp->foot, "the fingers open where they closed", now, "dropped", reason);
  else
    learning_ended("dropped", reason, now);
  return false;
}

// Config::grip_width_*: fingers closed much narrower or held much wider than the object is wide
// where they closed did not take it by its middle. Empty when the grip is plausible or unchecked.
std::string Supervisor::grip_off_the_axis(double opening) const {
  const std::optional<double>& expected = attempt_->expected_grip_width_m;
  if (!expected || config_.grip_width_high <= 0) return "";
  const std::string measured = "the fingers closed to " + mm(opening) + " on an object " + mm(*expected) + " wide";
  if (opening < config_.grip_width_low * *expected) return "grasped off its axis: " + measured + " (an edge pinched)";
  if (opening > config_.grip_width_high * *expected + config_.grip_width_slack_m)
    return "grasped off its axis: " + measured + " (a finger on its rim or inside it)";
  return "";
}

void Supervisor::on_learning_arm_state(const ArmStatus& arm, int64_t now) {
  using Motion = ArmStatus::Motion;
  if (arm.motion == Motion::Moving || arm.motion == Motion::Idle) return;
  learn_seq_ = 0;
  const std::string what = state_ == State::Grasp ? "grasp" : state_ == State::Rotate ? "wrist turn" : "place";
  if (arm.motion == Motion::Refused && state_ == State::Grasp) {
    arm_away_ = false;  // nothing moved
    return learning_ended("not grasped", "arm refused the grasp: " + arm.last_error, now);
  }
  if (state_ == State::Place) {
    if (arm.motion == Motion::Done && pending_place_is_put_back_) attempt_->put_back_at = pending_place_;
    const std::string how = arm.motion == Motion::Done ? "" : "; the arm did not put it back (" + arm.last_error + ")";
    return learning_ended(pending_learning_, pending_reason_ + how, now);
  }
  if (arm.motion == Motion::Stopped) return learning_ended("arm failed", "arm stopped during the " + what + ": " + arm.last_error, now);
  if (arm.motion == Motion::Refused) {  // the wrist can turn no further: learn from the views so far
    attempt_->learning_reason = "the arm refused the wrist turn after view " + std::to_string(attempt_->views.size()) + ": " + arm.last_error;
    return commit_views(now);
  }
  if (!holding(arm, state_ == State::Grasp ? "after the grasp" : "after turn " + std::to_string(attempt_->views.size()), now)) return;
  if (state_ == State::Grasp) {
    // Turn towards the side joint 6 has room on for every step.
    const double total = (config_.views - 1) * config_.view_step_deg * M_PI / 180;
    const double step = config_.view_step_deg * M_PI / 180;
    wrist_step_ = joints_[5] + total <= arm_.model.limits.upper[5] ? step : -step;
  }
  request_time_ = now;
  enter(State::Rotate, now, "view " + std::to_string(attempt_->views.size() + 1) + " of " + std::to_string(config_.views));
  ask_for_still(now, true);
}

// One training view: the right still with the held object's box, to the learner and kept.
void Supervisor::take_view(const cv::Mat& still, int64_t utime, int64_t now) {
  Attempt& a = *attempt_;
  LearnView view;
  view.index = static_cast<int>(a.views.size());
  view.angle = view.index * wrist_step_;
  view.image = still.clone();
  view.utime = utime;
  view.object_key = a.object_key();
  // The held object spans the grasp height below the tool point, and up to its triangulated top
  // (the estimated top plus the lowering's uncertainty) above it.
  const Eigen::Vector3d tool = arm_.base.world_from_base() * robot::forward_kinematics(arm_.model, joints_).translation();
  view.box = cylinder_box(scene_, tool, config_.targets.object_radius, tool.z() - a.grasp->grasp_height_m,
                          tool.z() + a.grasp->top.z() - a.grasp->grasp_height_m, config_.still_size);
  a.views.push_back(view);
  outputs_.push_back(view);
  if (static_cast<int>(a.views.size()) >= config_.views) return commit_views(now);
  learn_seq_ = next_seq_++;
  enter(State::Rotate, now, "turning the wrist " + std::to_string(static_cast<int>(std::lround(wrist_step_ * 180 / M_PI))) + " deg");
  outputs_.push_back(RotateCommand{learn_seq_, wrist_step_});
}

// Config::standing_view: the after still as the last view, boxed by the right segmentation.
bool Supervisor::add_standing_view(Attempt& a) {
  if (a.after.empty() || a.before.empty() || a.segmentation.mask.empty() || a.after.size() != a.views.front().image.size() ||
      a.segmentation.mask.size() != a.after.size())
    return false;
  const cv::Rect box = cv::boundingRect(a.segmentation.mask);
  if (box.empty()) return false;
  LearnView view;
  view.index = static_cast<int>(a.views.size());
  view.angle = 0;  // not turned: standing as the nudge left it
  view.box = box;
  view.image = a.after.clone();
  // The object's outline against its neighbours moves with it from scene to scene: the learner
  // keeps only what lies inside the segmentation (docs/learning.md rule 5).
  view.mask = a.segmentation.mask.clone();
  view.utime = a.after_utime;
  view.object_key = a.object_key();
  a.views.push_back(view);
  outputs_.push_back(view);
  return true;
}

void Supervisor::commit_views(int64_t now) {
  Attempt& a = *attempt_;
  if (a.views.empty()) return place(now, "not learned", "no view was taken");
  const bool standing = config_.standing_view && add_standing_view(a);
  // The scene still; without it the learner prunes across the views only. With the standing view
  // the before still: the after still would prune that view's object as scene.
  const cv::Mat& scene_still = standing ? a.before : a.after;
  if (!scene_still.empty()) {
    LearnView scene;
    scene.scene = true;
    scene.image = scene_still;
    scene.utime = standing ? a.before_utime : a.after_utime;
    scene.object_key = a.object_key();
    outputs_.push_back(scene);
  }
  learn_seq_ = next_seq_++;
  enter(State::Learn, now, "learning from " + std::to_string(a.views.size()) + " views");
  const double height = a.grasp->top_height_m;
  outputs_.push_back(LearnCommit{learn_seq_, a.object_key(), static_cast<int>(a.views.size()), height, config_.grasp.top_radius_m});
}

void Supervisor::on_learned(int64_t seq, bool ok, const std::string& name, const std::string& reason, int64_t now) {
  if (state_ != State::Learn || seq != learn_seq_) return;
  learn_seq_ = 0;
  if (ok) attempt_->learned_name = name;
  place(now, ok ? "learned" : "learn failed", ok ? "learned as '" + name + "'" : reason);
}

void Supervisor::on_learner_status(const std::string& status, int64_t now) {
  if (state_ != State::Learn) return;
  const std::string busy = "learning " + attempt_->object_key();
  if (status.rfind(busy, 0) == 0 && (status.size() == busy.size() || status[busy.size()] == ' '))
    learner_busy_ = now;
}

// Sec. 7.2.3: the object goes back where it stood before the nudge (revisits stay possible).
void Supervisor::place(int64_t now, const std::string& learning, const std::string& reason) {
  const Eigen::Vector3d before_nudge = where_it_stood(*attempt_);
  put_down(before_nudge, "putting the object back at " + millimetres(before_nudge), now, learning, reason);
  pending_place_is_put_back_ = true;
}

// Where the object stood before the nudge: the candidate, unless the stable stereo mismatch that
// the mask's foot moved the rest off (Attempt::rest_from_axes) put the candidate as far off (the
// white bottle's, 5 cm behind it along the ray). Whether it did, the push tells: the object went
// along it, about push_travel_m, so it stood there back from its rest. The demo's mug and bottle
// showed the settled axes off while the candidate was right (the candidate moved by the axes' error
// would have put them back 2 and 8 cm from where they stood). A rest placed along the push from the
// candidate (rest_from_still) says nothing against the candidate.
Eigen::Vector3d Supervisor::where_it_stood(const Attempt& a) const {
  const Eigen::Vector3d& candidate = a.target.position;
  if (!a.rest || !a.rest_from_axes || a.rest_from_still) return candidate;
  const Eigen::Vector3d shared_mismatch = candidate + (*a.rest - *a.rest_from_axes);
  const Eigen::Vector3d pushed_from = *a.rest - config_.push_travel_m * a.direction.normalized();
  const auto off = [&](const Eigen::Vector3d& p) { return (p - pushed_from).head<2>().norm(); };
  return off(shared_mismatch) < off(candidate) ? shared_mismatch : candidate;
}

void Supervisor::put_down(const Eigen::Vector3d& where, const std::string& what, int64_t now, const std::string& learning,
                          const std::string& reason) {
  Attempt& a = *attempt_;
  pending_learning_ = learning;
  pending_reason_ = a.learning_reason.empty() ? reason : a.learning_reason + "; " + reason;
  pending_place_ = where;
  pending_place_is_put_back_ = false;  // place() says when it is
  learn_seq_ = next_seq_++;
  enter(State::Place, now, what + " (" + learning + ")");
  outputs_.push_back(PlaceCommand{learn_seq_, where, a.grasp->grasp_height_m});
}

void Supervisor::learning_ended(const std::string& learning, const std::string& reason, int64_t now) {
  Attempt& a = *attempt_;
  a.learning = learning;
  a.learning_reason = reason;
  ++summary_.learning[learning];
  if (learning == "learned") ++summary_.learned;
  end_attempt(Outcome::Segmented, "segmented; " + learning + (reason.empty() ? "" : ": " + reason), now);
}

}  // namespace nudge::supervisor
