// supervisor: the autonomous segmentation loop (thesis ch. 6, fig. 6.2). A thin shell around
// nudge::supervisor::Supervisor: it turns messages into the state machine's inputs, its outputs
// into messages and files, keeps the task clock, watches every required service's heartbeat, and
// writes the whole run to an LCM log named by the run id with a JSON summary beside it.
// docs/supervisor.md has the protocol (channels in and out, and why).
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/atomic_file.hpp"
#include "nudge/axes_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/service.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/learn_commit_t.hpp"
#include "nudge/learn_result_t.hpp"
#include "nudge/learn_view_t.hpp"
#include "nudge/recognition_t.hpp"
#include "nudge/recognize_request_t.hpp"
#include "nudge/log.hpp"
#include "nudge/robot/workspace_flags.hpp"
#include "nudge/segmentation_t.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/snapshot_request_t.hpp"
#include "nudge/supervisor/report.hpp"
#include "nudge/supervisor/segment.hpp"
#include "nudge/supervisor/supervisor.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/timing.hpp"

using namespace nudge;
namespace sv = nudge::supervisor;

namespace {

struct Options {
  std::string calibration, run_id, out_dir = "out/runs", clock = "sim", require;
  // Two missed beats (heartbeats at 1 Hz): a killed service is noticed within 3 s whatever its
  // heartbeat's phase (as the services' own watch, kSilentAfterUs).
  double service_timeout_s = 2.5;
  int first_seq = 0;
  // A gentle push: tall objects (bottles) tip when the pad meets them at the arm's usual speed.
  double nudge_speed_scale = 0.25;
  bool keep_running = false;
  std::string standing_view = "off";     // Config::standing_view
  std::string line_pick = "strongest";  // strongest, nearest (LineSearchParams::strongest)
  std::string candidate_order = "nearest";  // nearest, support (TargetParams::order)
  int rest_from_still = 1;               // Config::rest_from_still
  int rival_by_foot = 1;                 // Config::rival_by_foot
  int graspable_push_first = 1;          // Config::graspable_push_first
  int spare_doubtful = 1;                // TargetParams::spare_doubtful
  int defer_for_doubtful = 1;            // TargetParams::defer_for_doubtful
  std::string learn = "auto";      // on, off, auto (while the learner's heartbeat is heard)
  std::string learner = "learner"; // the learner service's heartbeat name
  sv::Config config;
  sv::ArmSetup arm;
};

std::string default_run_id() {
  const std::time_t t = std::time(nullptr);
  char text[32];
  std::strftime(text, sizeof text, "run-%Y%m%d-%H%M%S", std::gmtime(&t));
  return text;
}

std::set<std::string> split(const std::string& list) {
  std::set<std::string> items;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');)
    if (!item.empty()) items.insert(item);
  return items;
}

sv::ArmStatus::Motion motion_of(int8_t motion) {
  switch (motion) {
    case arm_state_t::MOTION_MOVING: return sv::ArmStatus::Motion::Moving;
    case arm_state_t::MOTION_DONE: return sv::ArmStatus::Motion::Done;
    case arm_state_t::MOTION_REFUSED: return sv::ArmStatus::Motion::Refused;
    case arm_state_t::MOTION_STOPPED: return sv::ArmStatus::Motion::Stopped;
    default: return sv::ArmStatus::Motion::Idle;
  }
}

void copy3(const Eigen::Vector3d& v, double* out) {
  for (int i = 0; i < 3; ++i) out[i] = v[i];
}

// The run's LCM log: every event the supervisor receives, in the order it handles them (so that a
// replay re-derives the same states), under a temporary name until the run ends.
class RunLog {
 public:
  explicit RunLog(const std::string& path)
      : path_(path), partial_(path + ".partial"), file_(std::make_unique<lcm::LogFile>(partial_, "w")) {
    if (!file_->good()) throw std::runtime_error(partial_ + ": cannot open the run's log for writing");
  }
  void write(int64_t utime, const std::string& channel, const void* data, size_t size) {
    lcm::LogEvent event;
    event.eventnum = 0;
    event.timestamp = utime;
    event.channel = channel;
    event.datalen = static_cast<int32_t>(size);
    event.data = const_cast<void*>(data);
    if (file_) file_->writeEvent(&event);
  }
  void close() {
    if (!file_) return;
    file_.reset();  // flushes and closes
    std::filesystem::rename(partial_, path_);
  }
  const std::string& path() const { return path_; }

 private:
  std::string path_, partial_;
  std::unique_ptr<lcm::LogFile> file_;
};

// Published by the supervisor alone.
const std::set<std::string> kOwnChannels = {bus::channel::CANDIDATES_REQUEST, bus::channel::CAMERA_SNAPSHOT_REQUEST,
                                            bus::channel::ARM_COMMAND, bus::channel::SUPERVISOR_STATE,
                                            bus::channel::SEGMENTATION, bus::channel::RECOGNIZE_REQUEST,
                                            bus::channel::LEARN_VIEW, bus::channel::LEARN_COMMIT};

class Shell {
 public:
  Shell(bus::Service& service, Options& opt)
      : service_(service), opt_(opt), scene_(sv::SceneGeometry::load(opt.calibration)),
        supervisor_(opt.config, scene_, opt.arm, sv::motion_segmentation()),
        required_(split(opt.require)), run_dir_(opt.out_dir + "/" + opt.run_id) {
    // Its own scratch images: a thread of its own; no stages (only the right camera's are written).
    supervisor_.set_left_segmentation(sv::motion_segmentation({}, false));
    supervisor_.set_stageless_segmentation(sv::motion_segmentation({}, false));  // the grasp's (right) one
    supervisor_.warm_up();  // their memory touched now, not on the first grasp plan's clock
    std::error_code error;
    std::filesystem::create_directories(run_dir_, error);
    if (error) throw std::runtime_error(run_dir_ + ": cannot create the run's folder (" + error.message() + ")");
    log_ = std::make_unique<RunLog>(run_dir_ + "/" + opt.run_id + ".lcmlog");
    log::info() << "run " << opt.run_id << ": files in " << run_dir_ << "; waiting for " << opt.require;
  }

  void subscribe() {
    // The log holds exactly what the handlers were given, in that order: the typed subscriptions'
    // messages through their tap (a stream handler that fell behind skips frames, and so does
    // the log), every other channel through a catch-all. That one keeps LCM's queue of 30: without
    // a limit it would hold every camera frame the stream handlers skip until it is handled, and
    // defeat their skipping (what it drops are channels the loop does not read).
    auto& subs = service_.subscriptions();
    subs.set_tap([this](const lcm::ReceiveBuffer* rbuf, const std::string& channel) { record(rbuf, channel); });
    service_.input().subscribe(".*", &Shell::record_unhandled, this);
    subs.subscribe<heartbeat_t>(bus::channel::HEARTBEAT, [this](const heartbeat_t& m, const std::string&) { on_heartbeat(m); });
    subs.subscribe<sim_state_t>(bus::channel::SIM_STATE, [this](const sim_state_t& m, const std::string&) { on_sim_state(m); });
    subs.subscribe<candidates_t>(bus::channel::CANDIDATES, [this](const candidates_t& m, const std::string&) { on_candidates(m); });
    subs.subscribe<arm_state_t>(bus::channel::ARM_STATE, [this](const arm_state_t& m, const std::string&) { on_arm_state(m); });
    subs.subscribe<axes_t>(bus::channel::AXES, [this](const axes_t& m, const std::string&) { on_axes(m); });
    subs.subscribe<symmetry_lines_t>(bus::channel::SYMMETRY_LEFT, [this](const symmetry_lines_t& m, const std::string&) { on_lines(true, m); });
    subs.subscribe<symmetry_lines_t>(bus::channel::SYMMETRY_RIGHT, [this](const symmetry_lines_t& m, const std::string&) { on_lines(false, m); });
    subs.subscribe<image_t>(bus::channel::CAMERA_RIGHT, [this](const image_t& m, const std::string&) { on_frame(m); });
    subs.subscribe<image_t>(bus::channel::CAMERA_LEFT, [this](const image_t& m, const std::string&) { on_left_frame(m); });
    subs.subscribe<image_t>(bus::channel::SNAPSHOT_RIGHT, [this](const image_t& m, const std::string&) { on_still(m); });
    subs.subscribe<image_t>(bus::channel::SNAPSHOT_LEFT, [this](const image_t& m, const std::string&) { on_left_still(m); });
    subs.subscribe<recognition_t>(bus::channel::RECOGNITION, [this](const recognition_t& m, const std::string&) {
      // The match picture is decoded only for an answer the loop is waiting for.
      const bool awaited = supervisor_.state() == sv::State::Recognise && m.seq == supervisor_.awaited_learn_seq();
      cv::Mat picture;
      if (awaited && m.match_picture.size > 0) picture = bus::to_mat(m.match_picture);
      supervisor_.on_recognition(m.seq, m.label, m.reason, now_, picture);
      drain();
    });
    subs.subscribe<learn_result_t>(bus::channel::LEARNED, [this](const learn_result_t& m, const std::string&) {
      supervisor_.on_learned(m.seq, m.ok, m.object_name, m.reason, now_);
      drain();
    });
  }

  // Wall-clock duties: the task clock (--clock wall), the 1 Hz state, the heartbeat watchdog live.
  int tick() {
    const int64_t wall = wall_utime();
    if (opt_.clock == "wall") advance(wall);
    if (!service_.input_is_log()) check_services(wall);
    if (wall >= next_state_publish_ && started_) {
      publish_state(supervisor_.report());
      next_state_publish_ = wall + 1000000;
    }
    return 20;
  }

  bool refused() const { return refused_; }

  void finish_interrupted() {
    if (!finished_) {
      log::info() << "interrupted in " << sv::to_string(supervisor_.state());
      write_summary("interrupted in " + std::string(sv::to_string(supervisor_.state())));
    }
    log_->close();
  }

 private:
  // ---- inputs ----
  // What the supervisor publishes is logged when published (the loop's own echo would come after
  // the last message of a run, which the run does not wait for): skipped here.
  void record(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (kOwnChannels.count(channel)) return;
    log_->write(rbuf->recv_utime, channel, rbuf->data, rbuf->data_size);
  }
  void record_unhandled(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (!service_.subscriptions().has_typed(channel)) record(rbuf, channel);
  }

  template <typename Msg>
  void publish(const std::string& channel, const Msg& msg) {
    service_.publish(channel, msg);
    std::vector<uint8_t> bytes(msg.getEncodedSize());
    msg.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    log_->write(wall_utime(), channel, bytes.data(), bytes.size());
  }

  void on_heartbeat(const heartbeat_t& m) {
    if (m.service == "supervisor" && m.pid != getpid() && !service_.input_is_log() && !started_ && !refused_) {
      // Two loops commanding one arm would fight: the second one to start gives way.
      refused_ = true;
      log::error() << "another supervisor (pid " << m.pid << ") runs on this bus: refusing to start";
      service_.request_stop();
      return;
    }
    if (m.utime + 1000000 < newest_beat_) {
      // The replayed log went back (restarted, or the next of two logs): every service counts as
      // heard now, not as silent until the stamps catch up with the old ones.
      for (auto& [name, beat] : last_beat_) beat = std::min(beat, m.utime);
      newest_beat_ = m.utime;
    }
    last_beat_[m.service] = m.utime;
    newest_beat_ = std::max(newest_beat_, m.utime);
    // "learning <object_key> ..." keeps LEARN waiting while the learner works on the object.
    if (m.service == opt_.learner) supervisor_.on_learner_status(m.status, now_);
    check_services(service_.input_is_log() ? newest_beat_ : wall_utime());
  }

  void on_sim_state(const sim_state_t& m) {
    if (opt_.clock == "sim") advance(m.utime);
  }

  void on_candidates(const candidates_t& m) {
    std::vector<sv::Candidate> candidates;
    for (int i = 0; i < m.num_candidates; ++i) {
      const Eigen::Vector3d p(m.position[i][0], m.position[i][1], m.position[i][2]);
      if (!p.allFinite()) throw std::runtime_error("candidate " + std::to_string(i) + " has a non-finite position");
      candidates.push_back({i, scene_.table_to_world(p), m.cluster_size[i]});
    }
    supervisor_.on_candidates(candidates, m.utime, now_);
    drain();
  }

  void on_arm_state(const arm_state_t& m) {
    sv::ArmStatus status;
    status.motion = motion_of(m.motion);
    status.command_seq = m.command_seq;
    status.last_error = m.last_error;
    for (int i = 0; i < 6; ++i) status.joints[i] = m.joints[i];
    // The measured opening (what the fingers closed on), not the commanded one: a gripper that
    // closed on nothing measures ~0. No sensor (-1): no held-object check.
    status.gripper_opening = std::isfinite(m.gripper_measured) ? m.gripper_measured : -1.0;
    supervisor_.on_arm_state(status, now_);
    drain();
  }

  void on_axes(const axes_t& m) {
    if (supervisor_.state() != sv::State::Track) return;
    std::vector<sv::Axis> axes;
    for (const axis3d_t& a : m.axes) {
      const Eigen::Vector3d foot(a.table_point[0], a.table_point[1], a.table_point[2]);
      if (foot.allFinite() && std::isfinite(a.angle_to_normal)) axes.push_back({scene_.table_to_world(foot), a.angle_to_normal});
    }
    supervisor_.on_axes(axes, m.utime, now_);
    drain();
  }

  void on_lines(bool left, const symmetry_lines_t& m) {
    if (supervisor_.state() != sv::State::FindCandidates) return;
    std::vector<symmetry::Line> lines;
    for (const symmetry_line_t& line : m.lines) lines.push_back(bus::from_message(line));
    supervisor_.on_lines(left, lines, m.utime, now_);
  }

  // Decoding costs: a frame is decoded only when the loop would use it.
  void on_frame(const image_t& m) {
    if (!supervisor_.wants_frame(false)) return;
    supervisor_.on_right_frame(bus::to_mat(m), m.utime);
    drain();
  }
  void on_left_frame(const image_t& m) {
    if (!supervisor_.wants_frame(true)) return;
    supervisor_.on_left_frame(bus::to_mat(m), m.utime);
    drain();
  }

  void on_still(const image_t& m) {
    supervisor_.on_right_still(bus::to_mat(m), m.utime, now_);
    drain();
  }
  void on_left_still(const image_t& m) {
    supervisor_.on_left_still(bus::to_mat(m), m.utime, now_);
    drain();
  }

  // ---- time and health ----
  void advance(int64_t now) {
    // A stamp a little behind is another sender's clock or a late message: the clock stays. Far
    // behind, the world or the log restarted: the clock follows and the timeouts restart.
    constexpr int64_t kClockRestartUs = 1000000;
    if (started_ && now + kClockRestartUs < now_) {
      log::warn() << "the task clock went back " << (now_ - now) * 1e-6
                  << " s (a restarted world or log): the current step's timeout counts from now";
      now_ = now;
      supervisor_.on_clock_restart(now);
    }
    now_ = std::max(now_, now);
    // Live, listen for another supervisor's heartbeat (1 Hz) before taking the arm.
    if (!started_ && !service_.input_is_log() && wall_utime() < listen_until_) return;
    if (!started_) {
      started_ = true;
      const int64_t first_seq = opt_.first_seq > 0 ? opt_.first_seq : 1000 * (wall_utime() / 1000000 % 1000000) + 1;
      first_seq_ = first_seq;
      log::info() << "first ARM_COMMAND seq " << first_seq << " (--first-seq to replay this run)";
      silent_ = silent_services(service_.input_is_log() ? newest_beat_ : wall_utime());
      supervisor_.on_services(silent_, now_);
      supervisor_.start(now_, first_seq);
    }
    supervisor_.on_time(now_);
    drain();
  }

  // Required services not heard from within the limit of `reference` (live: the wall clock; in a
  // replay: the newest heartbeat's own time, so that the replay sees what the run saw).
  std::set<std::string> silent_services(int64_t reference) const {
    std::set<std::string> silent;
    for (const std::string& name : required_) {
      const auto it = last_beat_.find(name);
      if (it == last_beat_.end() || static_cast<double>(reference - it->second) > opt_.service_timeout_s * 1e6) silent.insert(name);
    }
    return silent;
  }

  void check_services(int64_t reference) {
    // The learner is not required: with --learn auto the loop learns while it is heard.
    const auto learner = last_beat_.find(opt_.learner);
    supervisor_.set_learner_alive(learner != last_beat_.end() &&
                                  static_cast<double>(reference - learner->second) <= opt_.service_timeout_s * 1e6);
    if (!started_) return;
    const std::set<std::string> silent = silent_services(reference);
    if (silent == silent_) return;
    silent_ = silent;
    supervisor_.on_services(silent_, now_);
    drain();
  }

  // ---- outputs ----
  void drain() {
    for (sv::Output& output : supervisor_.take_outputs()) std::visit([this](auto& o) { handle(o); }, output);
  }

  void handle(const sv::CandidatesRequest& r) {
    candidates_request_t m{};
    m.utime = now_;
    m.frames = r.frames;
    m.lines_per_image = r.lines;
    m.max_line_tilt_deg = r.max_line_tilt_deg;
    for (const Eigen::Vector3d& place : r.explored) {
      const Eigen::Vector3d p = scene_.world_to_table(Eigen::Vector3d(place.x(), place.y(), 0.0));
      m.explored.push_back({p.x(), p.y(), 0.0});  // on the table
    }
    m.num_explored = static_cast<int32_t>(m.explored.size());
    publish(bus::channel::CANDIDATES_REQUEST, m);
  }
  void handle(const sv::SnapshotRequest& r) {
    snapshot_request_t m{};
    m.utime = now_;
    m.cameras = r.both ? snapshot_request_t::CAMERAS_BOTH : snapshot_request_t::CAMERAS_RIGHT;
    publish(bus::channel::CAMERA_SNAPSHOT_REQUEST, m);
  }
  // A command with the fields every command shares (an identity orientation: a valid pose_t).
  arm_command_t arm_command(int64_t seq, int8_t command) const {
    arm_command_t m{};
    m.utime = now_;
    m.seq = seq;
    m.command = command;
    m.target.orientation[0] = 1;
    return m;
  }
  void handle(const sv::NudgeCommand& c) {
    arm_command_t m = arm_command(c.seq, arm_command_t::COMMAND_NUDGE);
    m.speed_scale = opt_.nudge_speed_scale;
    copy3(c.target, m.target.position);
    copy3(c.direction, m.direction);
    m.approach_height = opt_.arm.nudge.approach_height;
    m.height = opt_.arm.nudge.push_height;
    m.start_distance = opt_.arm.nudge.start_distance;
    m.stop_distance = opt_.arm.nudge.stop_distance;
    m.object_height = c.object_height;  // 0: the arm's own (the tallest object expected)
    publish(bus::channel::ARM_COMMAND, m);
  }
  void handle(const sv::HomeCommand& c) {
    publish(bus::channel::ARM_COMMAND, arm_command(c.seq, arm_command_t::COMMAND_HOME));  // the arm's usual speed
  }
  // Grasp and place: the tool's x axis along world x (an identity orientation), the fingers
  // `height` above the table over the object's foot.
  void handle(const sv::GraspCommand& c) {
    arm_command_t m = arm_command(c.seq, arm_command_t::COMMAND_GRASP);
    copy3(c.position, m.target.position);
    m.height = c.height;
    publish(bus::channel::ARM_COMMAND, m);
  }
  void handle(const sv::PlaceCommand& c) {
    arm_command_t m = arm_command(c.seq, arm_command_t::COMMAND_PLACE);
    copy3(c.position, m.target.position);
    m.height = c.height;
    publish(bus::channel::ARM_COMMAND, m);
  }
  void handle(const sv::RotateCommand& c) {
    arm_command_t m = arm_command(c.seq, arm_command_t::COMMAND_ROTATE_WRIST);
    m.angle = c.angle;
    publish(bus::channel::ARM_COMMAND, m);
  }
  void handle(const sv::RecognizeRequest& r) {
    recognize_request_t m{};
    m.utime = now_;
    m.seq = r.seq;
    const int roi[4] = {r.roi.x, r.roi.y, r.roi.width, r.roi.height};
    std::copy(roi, roi + 4, m.roi);
    m.want_match_picture = true;  // kept in the attempt's folder and shown in its report
    m.image = bus::to_message(r.image, image_t::FORMAT_PNG, now_, r.seq, "right");
    publish(bus::channel::RECOGNIZE_REQUEST, m);
  }
  void handle(const sv::LearnView& v) {
    learn_view_t m{};
    m.utime = v.utime;
    m.run_id = opt_.run_id;
    m.object_key = v.object_key;
    m.view_index = v.scene ? -1 : v.index;
    m.wrist_angle = v.angle;
    const int box[4] = {v.box.x, v.box.y, v.box.width, v.box.height};
    std::copy(box, box + 4, m.box);
    m.image = bus::to_message(v.image, image_t::FORMAT_PNG, v.utime, v.index, "right");
    m.kind = v.scene ? learn_view_t::KIND_SCENE : learn_view_t::KIND_VIEW;
    if (!v.mask.empty()) m.mask = bus::to_message(v.mask, image_t::FORMAT_PNG, v.utime, v.index, "right");
    if (v.scene) {  // the after (or, with the standing view, the before) still, already in the attempt's folder
      publish(bus::channel::LEARN_VIEW, m);
      log::info() << "the scene still sent for pruning the views' background";
      return;
    }
    const std::string file = sv::save_view(run_dir_, supervisor_.report().attempt, v);
    publish(bus::channel::LEARN_VIEW, m);
    log::info() << "view " << v.index << " (" << v.angle * 180 / M_PI << " deg) sent and saved as " << file;
  }
  void handle(const sv::LearnCommit& c) {
    learn_commit_t m{};
    m.utime = now_;
    m.seq = c.seq;
    m.run_id = opt_.run_id;
    m.object_key = c.object_key;
    m.object_name = "";
    m.num_views = c.views;
    m.height = c.height;
    m.radius = c.radius;
    publish(bus::channel::LEARN_COMMIT, m);
  }
  void handle(const sv::StopCommand& c) {
    publish(bus::channel::ARM_COMMAND, arm_command(c.seq, arm_command_t::COMMAND_STOP));
    log::warn() << "arm stopped: " << c.reason;
  }
  void handle(const sv::StateReport& r) {
    publish_state(r);
    log::info() << "[attempt " << r.attempt << "] " << sv::to_string(r.state) << ": " << r.reason;
    service_.set_status(std::string(sv::to_string(r.state)) + ": " + r.reason);
  }
  void handle(const sv::AttemptEnded& e) {
    const sv::Attempt& a = *e.attempt;
    const std::string folder = sv::save_attempt(run_dir_, a, opt_.arm, scene_.right_camera_in_world());
    attempts_json_.push_back(sv::attempt_json(a));
    log::info() << "attempt " << a.number << ": " << sv::to_string(a.outcome) << " (" << a.reason << "), files in " << folder;
    if (a.outcome == sv::Outcome::Segmented) publish_segmentation(a);
  }
  void handle(const sv::Finished& f) {
    finished_ = true;
    write_summary(f.summary.end_reason);
    log::info() << "run " << opt_.run_id << " ended: " << f.summary.segmented << " objects segmented in "
                << f.summary.attempts << " attempts; " << f.summary.end_reason;
    if (!opt_.keep_running) service_.request_stop();
  }

  void publish_state(const sv::StateReport& r) {
    supervisor_state_t m{};
    m.utime = now_;
    m.run_id = opt_.run_id;
    m.state = static_cast<int8_t>(r.state);
    m.state_name = sv::to_string(r.state);
    m.attempt = r.attempt;
    m.candidate_index = r.candidate_index;
    m.num_candidates = r.num_candidates;
    copy3(r.target, m.target);
    m.reason = r.reason;
    m.segmented = r.segmented;
    m.failed_attempts = r.failed_attempts;
    m.rejected = r.rejected;
    publish(bus::channel::SUPERVISOR_STATE, m);
  }

  void publish_segmentation(const sv::Attempt& a) {
    segmentation_t m{};
    m.utime = a.after_utime;  // the still the mask is cut from (published later, after any learning)
    m.run_id = opt_.run_id;
    m.attempt = a.number;
    copy3(a.target.position, m.position_before);
    copy3(*a.rest, m.position_after);
    m.line_before = bus::to_message(*a.before_line);
    m.line_after = bus::to_message(*a.after_line);
    m.mask_pixels = cv::countNonZero(a.segmentation.mask);
    m.mask = bus::to_message(a.segmentation.mask, image_t::FORMAT_PNG, a.after_utime, a.number, "right");
    publish(bus::channel::SEGMENTATION, m);
  }

  void write_summary(const std::string& end_reason) {
    sv::Summary summary = supervisor_.summary();
    summary.end_reason = end_reason;
    write_file_atomically(run_dir_ + "/summary.json",
                          sv::summary_json(opt_.run_id, first_seq_, summary, attempts_json_) + "\n");
  }

  bus::Service& service_;
  Options& opt_;
  sv::SceneGeometry scene_;
  sv::Supervisor supervisor_;
  std::set<std::string> required_, silent_;
  std::string run_dir_;
  std::unique_ptr<RunLog> log_;
  std::map<std::string, int64_t> last_beat_;
  int64_t newest_beat_ = 0, now_ = 0, next_state_publish_ = 0, first_seq_ = 0;
  bool started_ = false, finished_ = false, refused_ = false;
  const int64_t listen_until_ = wall_utime() + 1500000;  // 1.5 heartbeat periods after start-up
  std::vector<std::string> attempts_json_;
};

void add_flags(Flags& f, Options& o) {
  f.add_string("calibration", &o.calibration, "calibration file: stereo rig, table_plane, arm_base, arm_to_right_* (required)");
  f.add_string("run-id", &o.run_id, "names the run's folder, log and summary (default: run-<UTC time>)");
  f.add_string("out", &o.out_dir, "folder for the runs' folders");
  f.add_string("clock", &o.clock, "task clock: sim (SIM_STATE utime) or wall");
  f.add_string("require", &o.require, "services whose heartbeats the loop needs, comma-separated (default: camera,symmetry,triangulation,arm, plus world with --clock sim)");
  f.add_double("service-timeout", &o.service_timeout_s, "a required service silent this long pauses the run and stops the arm, s");
  f.add_bool("keep-running", &o.keep_running, "stay up after the run ends (default: exit)");
  f.add_bool("track", &o.config.track,
             "start a symmetry tracker per camera at the target's line when it moves and judge the result by the "
             "tracked lines (thesis 6.3.2; default: by the settled AXES, docs/supervisor.md)");
  f.add_bool("track-trace", &o.config.track_trace,
             "run the trackers and keep their per-frame states (attempt.json's track_trace, the report's tracking "
             "plot) while the settled AXES decide");
  f.add_int("survey-frames", &o.config.survey_frames, "stereo pairs per candidate survey (thesis 25)");
  f.add_int("survey-lines", &o.config.survey_lines, "lines per image in a survey (thesis 3)");
  f.add_int("agreement-lines", &o.config.agreement_lines,
            "a candidate's stereo agreement counts each image's lines up to this many not of an explored object "
            "(the symmetry service may publish more for later surveys)");
  f.add_double("wide-survey-tilt", &o.config.wide_survey_tilt_deg,
               "a survey leaving nothing to nudge is asked again with lines up to DEG from upright before the run ends (0: never)");
  f.add_int("max-attempts", &o.config.max_attempts, "nudges per run");
  f.add_int("segmentation-retries", &o.config.segmentation_retries,
            "a push that moved something but gave no segmentation: nudge the object again from its rest, this many times");
  f.add_double("refine-target", &o.config.refine_target_max_m,
               "place the target anew from its lines in both cameras' before stills when that moves it at most this "
               "far, m, and plan its push there (0: off, the survey's place)");
  f.add_double("refine-window", &o.config.refine_window_px,
               "--refine-target: the lines searched for within this many px of the target's projected axis (stills' pixels)");
  f.add_double("retry-still-line-px", &o.config.retry_still_line_px,
               "but not when the segmentation is empty and the target's line stands within this many px (1280x960) "
               "and 1 deg of where it stood: nothing there moved (0: retried all the same)");
  f.add_double("settle", &o.config.settle_s, "after the nudge, wait this long for the object to rest, s");
  f.add_double("max-settle", &o.config.max_settle_s,
               "with too few settled axes near the push line, settle on up to this long after the nudge, s");
  f.add_double("rest-core", &o.config.rest_core_m,
               "the settled axes within this of the densest one give the nudged object's rest, m (0: the whole group's median)");
  f.add_double("rest-mask-disagreement", &o.config.rest_mask_disagreement_m,
               "after the segmentation, the after still's mask's foot is the rest when the settled axes' rest is farther "
               "from it than this (and within the push window), m (0: the axes' rest stays)");
  f.add_double("min-nudge-agreement", &o.config.targets.min_nudge_agreement,
               "candidates that both cameras show upright in a smaller share of the survey's frames are not nudged (0: all are)");
  f.add_double("min-mask-share", &o.config.min_mask_share,
               "a mask smaller than this share of the smallest object's image at the rest (its pixels, rows or mean width) is no segmentation (0: any)");
  f.add_double("doubtful-tilt", &o.config.doubtful_tilt_deg,
               "a rest leaning more than this (deg, within the upright limit) must show an upright object's base in its mask, "
               "or the attempt ends tipped or lost (0: off)");
  f.add_double("max-object-half-width", &o.config.max_object_half_width_m,
               "mask pixels farther than this from the object's after line (m, projected at its rest) are something else "
               "that moved and are cleared (0: kept)");
  f.add_double("after-line-lean-window", &o.config.line_search.lean_window_deg,
               "the after still's object line is looked for first within this many deg of the before line's lean carried to "
               "the rest (0: only about the upright prediction)");
  f.add_int("still-lines", &o.config.line_search.lines,
            "symmetry peaks examined in a still's search for the object's line (the prediction's windows keep the nearby ones)");
  f.add_double("column-line-px", &o.config.line_search.not_object_px,
               "a still's line within this many px (and 1.5 deg) of the arm's base column's projected axis is the column's, "
               "not the object's (0: no such check)");
  f.add_double("push-travel", &o.config.push_travel_m,
               "an after line where the before line stood, with the rest not come along the push: the object's line is "
               "looked for this far along the push from where it stood, m (0: no such search; the lines agree within --column-line-px)");
  f.add_int("rest-from-still", &o.rest_from_still,
            "1: too few settled axes near the push line, though something moved, and the object is looked for as a new "
            "upright line along the push in the right after still (--push-travel along it); 0: tipped or lost at once");
  f.add_double("far-rest", &o.config.far_rest_m,
               "with --rest-from-still 1: a settled axes' rest farther than this along the push, about whose line the stills "
               "show no change, gives way to a new line along the push when one is found, m (0: never)");
  f.add_double("weak-after-line", &o.config.weak_after_line_share,
               "with --rest-from-still 1: an after line found about the settled axes' rest with less than this share of the "
               "before line's votes gives way to a stronger new line along the push when one is found (0: never)");
  f.add_int("rival-by-foot", &o.rival_by_foot,
            "1: a candidate on the target's right-camera line whose depth beyond the foot of the line in the before still is "
            "nearer --foot-depth-typical by --rival-margin is nudged instead; 0: the survey's choice stands");
  f.add_int("graspable-push-first", &o.graspable_push_first,
            "1: with learning, of the two ways across the view the one that leaves the object where the arm can grasp "
            "it (--push-travel along it) is tried first; 0: the same way first as without learning");
  f.add_double("pad-half-width", &o.config.targets.pad_half_width,
               "half the pad's width across the push, m: no other object may stand within it and --object-radius of "
               "the pad's path (the simulated pad's 0.04)");
  f.add_int("spare-doubtful", &o.spare_doubtful,
            "1: a push that also keeps its pad, the pushed object's slide and the arm's links clear of the candidates "
            "seen in too few frames to count as obstacles (--min-nudge-agreement or more) is taken first when the target "
            "has one; 0: those candidates are no obstacle");
  f.add_int("defer-for-doubtful", &o.defer_for_doubtful,
            "1: a candidate seen in enough frames, none of whose pushes keeps clear of a doubtful candidate not yet "
            "nudged, is tried after the other candidates (the doubtful ones among them); 0: in its place in the order");
  f.add_double("line-obstacles", &o.config.line_obstacle_share,
               "> 0: a place on the table that the survey's right-camera lines mark (the ray through each line's lowest "
               "pixel, --foot-depth-typical beyond) in at least this share of the frames is an obstacle every push keeps "
               "clear of, as of a candidate (an object the stereo pairing missed); 0: off");
  f.add_double("foot-depth-typical", &o.config.foot_depth_typical_m,
               "how far an object's axis stands beyond the table point under its line's lowest pixel (its radius), m");
  f.add_double("rival-margin", &o.config.rival_margin_m,
               "with --rival-by-foot 1: how much nearer the typical depth a rival must stand to be nudged instead, m");
  f.add_double("rival-max-misfit", &o.config.rival_max_misfit_m,
               "with --rival-by-foot 1: a rival farther than this from --foot-depth-typical fits the foot no better, m");
  f.add_string("line-pick", &o.line_pick,
               "of the lines near a still's predicted object line: the strongest (most votes) or the nearest");
  f.add_double("min-mask-mirror", &o.config.min_mask_mirror_agreement,
               "a mask that agrees less with its own mirror image about the object's line (IoU) is no segmentation (0: any)");
  f.add_double("min-mask-side-edges", &o.config.min_mask_side_edges,
               "a mask with a side on an edge of the after still in fewer than this share of its rows is no segmentation (0: any)");
  f.add_double("snapshot-timeout", &o.config.snapshot_timeout_s, "for a still, s of the task clock");
  f.add_double("snapshot-retry", &o.config.snapshot_retry_s, "a still not come within this many s of the task clock is asked for again (a lost UDP fragment loses it)");
  f.add_double("candidates-timeout", &o.config.candidates_timeout_s, "for a CANDIDATES answer, s of the task clock");
  f.add_double("nudge-timeout", &o.config.nudge_timeout_s, "for the arm to finish a nudge, s of the task clock");
  f.add_double("nudge-speed", &o.nudge_speed_scale, "nudges at this fraction of the arm's joint speed limits (0.01-1)");
  f.add_double("object-radius", &o.config.targets.object_radius, "largest expected object radius (push clearance), m");
  f.add_double("shortest-height-limit", &o.config.targets.shortest_height_limit,
               "a push whose arm would pass too near the tallest expected object is still chosen when it clears an object "
               "at least this tall, m; the object's height is then measured in the before still (0: never)");
  f.add_double("max-push-turn", &o.config.targets.max_push_turn_deg,
               "when neither push across the camera's view plans, pushes turned off it up to this are tried, deg (0: across only)");
  f.add_double("push-turn-step", &o.config.targets.push_turn_step_deg, "the turned pushes' step, deg");
  f.add_double("obstacle-height", &o.config.targets.obstacle_height,
               "the arm's links, along the whole push and the park after it, keep clear of every other known object taken "
               "this tall, m (0: not checked); a push that cannot is made only when none can");
  f.add_double("height-margin", &o.config.height.margin_m,
               "added to the object's measured height before the arm is told to clear it, m");
  f.add_string("candidate-order", &o.candidate_order,
               "the order candidates seen by both cameras are tried in: nearest (the right camera; the thesis) or support "
               "(most intersects first, nearest first among equals)");
  f.add_string("learn", &o.learn,
               "learning by interaction (thesis ch. 7: recognise before nudging; grasp, turn, learn, put back after a "
               "segmentation): on, off, or auto (while the learner's heartbeat is heard)");
  f.add_string("learner", &o.learner, "the learner service's heartbeat name (--learn auto)");
  f.add_int("views", &o.config.views, "training views per learned object (thesis 12)");
  f.add_double("view-step", &o.config.view_step_deg, "wrist turn between training views, deg (thesis 30)");
  f.add_string("standing-view", &o.standing_view,
               "on|off: also learn the after still (the object standing where the nudge left it) as the last view, pruned against the before still");
  f.add_double("recognise-timeout", &o.config.recognise_timeout_s, "for a RECOGNITION answer, s of the task clock (then the nudge goes ahead)");
  f.add_double("learn-timeout", &o.config.learn_timeout_s, "for a LEARNED answer, s of the task clock (then the object is put back); counted from the learner's last heartbeat saying it learns the object");
  f.add_double("learn-max-wait", &o.config.learn_max_wait_s, "for a LEARNED answer however long the learner's heartbeat says it is learning the object, s of the task clock");
  f.add_double("held-min-opening", &o.config.held_min_opening_m,
               "ARM_STATE.gripper_measured below this after a grasp or turn: nothing held (dropped), m; 0: no check "
               "(no check either when the arm reports no measurement, -1)");
  f.add_double("grip-width-low", &o.config.grip_width_low,
               "after a grasp the fingers closed narrower than this part of the object's width at the grasp height "
               "(its right segmentation): an edge pinched, put down again");
  f.add_double("grip-width-high", &o.config.grip_width_high,
               "after a grasp the fingers held wider than this part of the object's width (plus --grip-width-slack): "
               "a finger on its rim or inside it, put down again; 0: neither check");
  f.add_double("grip-width-slack", &o.config.grip_width_slack_m, "added to --grip-width-high's width, m");
  f.add_double("top-radius", &o.config.grasp.top_radius_m, "r of the grasp height's r*tan(theta) lowering, m (thesis: 36 mm at 30 deg)");
  f.add_double("grip-depth", &o.config.grasp.grip_depth_m,
               "the fingers' middle this far below the object's estimated top (short objects: half way up), m");
  f.add_int("first-seq", &o.first_seq, "first ARM_COMMAND seq (default: from the wall clock; set it to replay a run)");
}

}  // namespace

int main(int argc, char** argv) {
  return bus::guarded_main("supervisor", [&] {
    bus::Service service("supervisor",
                         "Autonomous segmentation by a robotic nudge (thesis ch. 6): survey, nudge, watch, segment,\n"
                         "with nobody in the loop. Writes the run's LCM log and summary under --out.");
    Options opt;
    add_flags(service.flags(), opt);
    // The arm's workspace, as nudge-arm reads it: the targets it chooses are nudges the arm accepts.
    const robot::WorkspaceFlags workspace_flags(
        service.flags(), {"base-height", "base-yaw-deg", "tool-length", "table-margin", "ring-inner", "ring-outer"});
    if (!service.parse(argc, argv)) return 0;
    const robot::Workspace workspace = workspace_flags.resolve();
    robot::apply_workspace(workspace, &opt.arm.model);
    robot::apply_workspace(workspace, &opt.arm.safety);
    opt.arm.base = robot::BaseFrame::of(workspace);
    if (opt.calibration.empty()) throw FlagError("--calibration FILE is required");
    if (opt.clock != "sim" && opt.clock != "wall") throw FlagError("--clock must be sim or wall, not '" + opt.clock + "'");
    if (opt.run_id.empty()) opt.run_id = default_run_id();
    if (opt.run_id.find('/') != std::string::npos) throw FlagError("--run-id must not contain '/'");
    if (opt.require.empty()) opt.require = std::string("camera,symmetry,triangulation,arm") + (opt.clock == "sim" ? ",world" : "");
    if (!(opt.service_timeout_s > 0)) throw FlagError("--service-timeout must be > 0");
    if (!(opt.config.learn_timeout_s > 0)) throw FlagError("--learn-timeout must be > 0");
    if (!(opt.config.wide_survey_tilt_deg >= 0 && opt.config.wide_survey_tilt_deg <= 90))
      throw FlagError("--wide-survey-tilt must be in [0, 90] degrees");
    if (!(opt.config.learn_max_wait_s >= opt.config.learn_timeout_s)) throw FlagError("--learn-max-wait must be >= --learn-timeout");
    if (!(opt.nudge_speed_scale >= 0.01 && opt.nudge_speed_scale <= 1)) throw FlagError("--nudge-speed must lie in [0.01, 1]");
    if (opt.line_pick != "strongest" && opt.line_pick != "nearest")
      throw FlagError("--line-pick: strongest or nearest, not '" + opt.line_pick + "'");
    opt.config.line_search.strongest = opt.line_pick == "strongest";
    if (opt.candidate_order != "nearest" && opt.candidate_order != "support")
      throw FlagError("--candidate-order: nearest or support, not '" + opt.candidate_order + "'");
    opt.config.targets.order =
        opt.candidate_order == "support" ? sv::TargetParams::Order::MostSupport : sv::TargetParams::Order::NearestCamera;
    if (opt.rest_from_still != 0 && opt.rest_from_still != 1) throw FlagError("--rest-from-still must be 0 or 1");
    if (!(opt.config.far_rest_m >= 0 && opt.config.far_rest_m <= opt.config.max_travel_m))
      throw FlagError("--far-rest must lie in [0, " + std::to_string(opt.config.max_travel_m) + "] m");
    if (!(opt.config.weak_after_line_share >= 0 && opt.config.weak_after_line_share <= 1))
      throw FlagError("--weak-after-line must lie in [0, 1]");
    opt.config.rest_from_still = opt.rest_from_still == 1;
    if (opt.rival_by_foot != 0 && opt.rival_by_foot != 1) throw FlagError("--rival-by-foot must be 0 or 1");
    if (!(opt.config.line_obstacle_share >= 0 && opt.config.line_obstacle_share <= 1))
      throw FlagError("--line-obstacles must be in [0, 1]");
    if (!(opt.config.targets.obstacle_height >= 0 && opt.config.targets.obstacle_height <= 2))
      throw FlagError("--obstacle-height must lie in [0, 2] m");
    if (!(opt.config.rival_margin_m >= 0)) throw FlagError("--rival-margin must be 0 or more");
    if (!(opt.config.rival_max_misfit_m >= 0)) throw FlagError("--rival-max-misfit must be 0 or more");
    opt.config.rival_by_foot = opt.rival_by_foot == 1;
    if (opt.graspable_push_first != 0 && opt.graspable_push_first != 1) throw FlagError("--graspable-push-first must be 0 or 1");
    opt.config.graspable_push_first = opt.graspable_push_first == 1;
    if (opt.spare_doubtful != 0 && opt.spare_doubtful != 1) throw FlagError("--spare-doubtful must be 0 or 1");
    if (!(opt.config.targets.pad_half_width > 0 && opt.config.targets.pad_half_width <= 0.2))
      throw FlagError("--pad-half-width must lie in (0, 0.2] m");
    opt.config.targets.spare_doubtful = opt.spare_doubtful == 1;
    if (opt.defer_for_doubtful != 0 && opt.defer_for_doubtful != 1) throw FlagError("--defer-for-doubtful must be 0 or 1");
    opt.config.targets.defer_for_doubtful = opt.defer_for_doubtful == 1;
    if (!(opt.config.line_search.not_object_px >= 0 && opt.config.line_search.not_object_px < 100))
      throw FlagError("--column-line-px must lie in [0, 100)");
    if (!(opt.config.push_travel_m >= 0 && opt.config.push_travel_m <= opt.config.max_travel_m))
      throw FlagError("--push-travel must lie in [0, " + std::to_string(opt.config.max_travel_m) + "] m");
    if (opt.config.line_search.lines < 1 || opt.config.line_search.lines > 100) throw FlagError("--still-lines must lie in [1, 100]");
    if (!(opt.config.line_search.lean_window_deg >= 0 && opt.config.line_search.lean_window_deg <= 90))
      throw FlagError("--after-line-lean-window must lie in [0, 90] deg");
    if (opt.learn == "on") opt.config.learn = sv::Config::Learn::On;
    else if (opt.learn == "off") opt.config.learn = sv::Config::Learn::Off;
    else if (opt.learn == "auto") opt.config.learn = sv::Config::Learn::Auto;
    else throw FlagError("--learn must be on, off or auto, not '" + opt.learn + "'");
    if (!(opt.config.rest_core_m >= 0 && opt.config.rest_core_m <= opt.config.same_axis_m))
      throw FlagError("--rest-core must lie in [0, 0.025] m (the group's own radius)");
    if (!(opt.config.rest_mask_disagreement_m >= 0 && opt.config.rest_mask_disagreement_m < 0.1))
      throw FlagError("--rest-mask-disagreement must lie in [0, 0.1) m");
    if (!(opt.config.targets.min_nudge_agreement >= 0 && opt.config.targets.min_nudge_agreement <= 1))
      throw FlagError("--min-nudge-agreement must lie in [0, 1]");
    if (!(opt.config.min_mask_share >= 0 && opt.config.min_mask_share <= 1)) throw FlagError("--min-mask-share must lie in [0, 1]");
    if (!(opt.config.doubtful_tilt_deg >= 0 && opt.config.doubtful_tilt_deg <= 90))
      throw FlagError("--doubtful-tilt must lie in [0, 90] deg");
    if (!(opt.config.max_object_half_width_m >= 0 && opt.config.max_object_half_width_m <= 0.5))
      throw FlagError("--max-object-half-width must lie in [0, 0.5] m");
    if (!(opt.config.min_mask_mirror_agreement >= 0 && opt.config.min_mask_mirror_agreement <= 1))
      throw FlagError("--min-mask-mirror must lie in [0, 1]");
    if (!(opt.config.min_mask_side_edges >= 0 && opt.config.min_mask_side_edges <= 1))
      throw FlagError("--min-mask-side-edges must lie in [0, 1]");
    if (!(opt.config.grip_width_low >= 0 && opt.config.grip_width_low < 1)) throw FlagError("--grip-width-low must lie in [0, 1)");
    if (!(opt.config.grip_width_high == 0 || (opt.config.grip_width_high > 1 && opt.config.grip_width_high < 10)))
      throw FlagError("--grip-width-high must be 0 (no check) or lie in (1, 10)");
    if (!(opt.config.grip_width_slack_m >= 0 && opt.config.grip_width_slack_m < 0.1)) throw FlagError("--grip-width-slack must lie in [0, 0.1) m");
    if (!(opt.config.held_min_opening_m >= 0 && opt.config.held_min_opening_m < 0.1)) throw FlagError("--held-min-opening must lie in [0, 0.1) m");
    static_assert(sv::GraspTargetParams{}.max_object_height_m == 0.35, "--grip-depth's message names the tallest object");
    if (!(opt.config.grasp.grip_depth_m >= 0 && opt.config.grasp.grip_depth_m < opt.config.grasp.max_object_height_m))
      throw FlagError("--grip-depth must lie in [0, 0.35) m (below the tallest object's top)");
    if (opt.config.views <= 0 || opt.config.views > 36) throw FlagError("--views must lie in [1, 36]");
    if (!(opt.config.view_step_deg > 0 && opt.config.view_step_deg <= 90)) throw FlagError("--view-step must lie in (0, 90] deg");
    if (opt.standing_view != "on" && opt.standing_view != "off") throw FlagError("--standing-view must be on or off");
    opt.config.standing_view = opt.standing_view == "on";
    Shell shell(service, opt);  // loads the calibration: a bad file ends here, naming the field
    service.start();
    shell.subscribe();
    const int code = service.run([&] { return shell.tick(); });
    shell.finish_interrupted();
    return shell.refused() ? 1 : code;
  });
}
