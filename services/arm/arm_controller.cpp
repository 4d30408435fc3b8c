#include "arm_controller.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <utility>

#include "nudge/bus/arm_convert.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/trajectory.hpp"

namespace nudge::arm {

namespace {

using robot::JointVector;

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

std::optional<robot::CommandKind> command_kind(int8_t code) {
  switch (code) {
    case arm_command_t::COMMAND_MOVE_JOINTS: return robot::CommandKind::MoveJoints;
    case arm_command_t::COMMAND_MOVE_POSE: return robot::CommandKind::MovePose;
    case arm_command_t::COMMAND_NUDGE: return robot::CommandKind::Nudge;
    case arm_command_t::COMMAND_GRASP: return robot::CommandKind::Grasp;
    case arm_command_t::COMMAND_OPEN: return robot::CommandKind::OpenGripper;
    case arm_command_t::COMMAND_CLOSE: return robot::CommandKind::CloseGripper;
    case arm_command_t::COMMAND_ROTATE_WRIST: return robot::CommandKind::RotateWrist;
    case arm_command_t::COMMAND_PLACE: return robot::CommandKind::Place;
    case arm_command_t::COMMAND_HOME: return robot::CommandKind::Home;
    default: return std::nullopt;
  }
}

std::string command_name(int8_t code) {
  if (code == arm_command_t::COMMAND_STOP) return "stop";
  if (const auto kind = command_kind(code)) return robot::command_name(*kind);
  return "command " + std::to_string(code);
}

// The planner's view of a message (same frame, same fields; the planner judges the content).
robot::Command to_command(const arm_command_t& m, robot::CommandKind kind) {
  robot::Command c;
  c.kind = kind;
  c.joints.assign(m.joints.begin(), m.joints.end());
  c.target_position = Eigen::Vector3d(m.target.position[0], m.target.position[1], m.target.position[2]);
  c.target_orientation = Eigen::Vector4d(m.target.orientation[0], m.target.orientation[1],
                                         m.target.orientation[2], m.target.orientation[3]);
  c.direction = Eigen::Vector3d(m.direction[0], m.direction[1], m.direction[2]);
  c.height = m.height;
  c.approach_height = m.approach_height;
  c.start_distance = m.start_distance;
  c.stop_distance = m.stop_distance;
  c.object_height = m.object_height;
  c.angle = m.angle;
  c.speed_scale = m.speed_scale;
  return c;
}

}  // namespace

void validate(const ControllerConfig& c) {
  robot::validate(c.planner);
  require(c.period_utime > 0, "state period must be positive");
  require(c.supervisor_timeout > 0 && std::isfinite(c.supervisor_timeout),
          "supervisor timeout must be positive");
}

ArmController::ArmController(ControllerConfig config, Backend backend)
    : config_(std::move(config)), backend_(std::move(backend)) {
  validate(config_);
  if (!backend_.driver || !backend_.advance) throw std::invalid_argument("backend without a driver");
}

// ---- time -----------------------------------------------------------------------------------

void ArmController::advance_to(int64_t utime, const Publish& publish) {
  if (!started_) {
    started_ = true;
    clock_ = backend_clock_ = utime;
    const int64_t period = config_.period_utime;
    next_publish_ = (utime / period + (utime % period > 0 ? 1 : 0)) * period;
  } else if (utime <= clock_) {
    return;
  }
  while (next_publish_ <= utime) {
    step_backend_to(next_publish_);
    clock_ = next_publish_;
    if (config_.max_catch_up_utime < 0 || utime - next_publish_ <= config_.max_catch_up_utime) {
      publish(state());
    }
    next_publish_ += config_.period_utime;
  }
  step_backend_to(utime);
  clock_ = utime;
}

void ArmController::advance_with_watchdog(int64_t utime, const Publish& publish) {
  const std::optional<int64_t> deadline = supervisor_deadline();
  if (deadline && *deadline <= utime) {
    advance_to(*deadline, publish);
    if (check_supervisor(*deadline)) publish(state());
  }
  advance_to(utime, publish);
}

void ArmController::step_backend_to(int64_t utime) {
  // Step in periods at most, so a step finishing mid-jump hands over to the next one on time.
  while (backend_clock_ < utime) {
    const int64_t dt = std::min(config_.period_utime, utime - backend_clock_);
    backend_.advance(dt * 1e-6);
    backend_clock_ += dt;
    update_motion();
  }
}

// ---- motion execution -----------------------------------------------------------------------

void ArmController::update_motion() {
  while (!steps_.empty()) {
    if (!step_started_) {
      if (!start_step(steps_.front())) return;  // aborted, with the reason
      step_started_ = true;
    }
    if (backend_.driver->read_joint_state().moving) return;
    steps_.pop_front();
    step_started_ = false;
  }
  if (motion_ == arm_state_t::MOTION_MOVING) {
    motion_ = arm_state_t::MOTION_DONE;
    running_.clear();
  }
}

bool ArmController::start_step(const Step& step) {
  robot::ArmDriver& driver = *backend_.driver;
  std::string refused;
  switch (step.kind) {
    case Step::Kind::Move: {
      const JointVector from = driver.read_joint_state().position;
      if (robot::joint_distance(from, step.goal) < 1e-12) return true;  // already there
      const robot::TrapezoidalMove move(from, step.goal,
                                        step.speed_scale * config_.planner.model.max_speed,
                                        step.speed_scale * config_.planner.model.max_acceleration);
      std::vector<robot::TimedJoints> targets;
      for (const robot::TimedJoints& sample :
           robot::sample_trajectory(move, config_.period_utime * 1e-6)) {
        if (sample.time > 0) targets.push_back(sample);
      }
      if (targets.empty()) return true;
      refused = driver.send_joint_targets(targets);
      break;
    }
    case Step::Kind::Path: {
      // The controller's LM command: linear joint interpolation between the planned waypoints.
      const robot::LinearTrajectory path =
          robot::LinearTrajectory::at_speed(step.path, config_.planner.model.max_speed, step.speed_scale);
      std::vector<robot::TimedJoints> targets;
      for (const robot::TimedJoints& waypoint : path.waypoints()) {
        if (waypoint.time > 0) targets.push_back(waypoint);
      }
      if (targets.empty()) return true;
      refused = driver.send_joint_targets(targets);
      break;
    }
    case Step::Kind::OpenGripper: refused = driver.open_gripper(); break;
    case Step::Kind::CloseGripper: refused = driver.close_gripper(); break;
  }
  if (!refused.empty()) {
    abort("the " + backend_.name + " backend refused " + step.what + ": " + refused);
    return false;
  }
  return true;
}

void ArmController::abort(const std::string& reason) {
  backend_.driver->stop();
  steps_.clear();
  step_started_ = false;
  running_.clear();
  motion_ = arm_state_t::MOTION_STOPPED;
  last_error_ = reason;
}

// ---- commands -------------------------------------------------------------------------------

arm_state_t ArmController::handle(const arm_command_t& command) {
  if (command.command == arm_command_t::COMMAND_STOP) {
    abort("stopped by COMMAND_STOP");
    command_seq_ = command.seq;
    return state();
  }
  if (busy()) {
    return refuse(command,
                  "busy: command " + std::to_string(command_seq_) + " (" + running_ +
                      ") is still moving; send COMMAND_STOP first",
                  false);
  }
  if (!supervisor_problem_.empty()) {
    return refuse(command, supervisor_problem_ + "; motions resume after the next supervisor heartbeat",
                  false);
  }
  if (config_.require_supervisor && !supervisor_seen_) {
    return refuse(command, "no supervisor heartbeat yet (--require-supervisor)", false);
  }
  const std::optional<robot::CommandKind> kind = command_kind(command.command);
  if (!kind) {
    return refuse(command, command_name(command.command) + ": unknown command code " + std::to_string(command.command),
                  true);
  }
  if (command.num_joints != static_cast<int32_t>(command.joints.size())) {
    return refuse(command, command_name(command.command) + ": num_joints " + std::to_string(command.num_joints) +
                               " but " + std::to_string(command.joints.size()) + " joints", true);
  }
  const JointVector current = backend_.driver->read_joint_state().position;
  const robot::MotionPlan p = robot::plan_command(config_.planner, to_command(command, *kind), current);
  if (!p.ok()) return refuse(command, command_name(command.command) + ": " + p.reason, p.malformed);

  steps_.assign(p.steps.begin(), p.steps.end());
  step_started_ = false;
  motion_ = arm_state_t::MOTION_MOVING;
  command_seq_ = command.seq;
  last_error_.clear();
  running_ = command_name(command.command);
  update_motion();  // starts the first step now; a command with nothing to do is done at once
  return state();
}

arm_state_t ArmController::refuse(const arm_command_t& command, const std::string& reason,
                                  bool malformed) {
  if (malformed) ++malformed_commands_;
  if (busy()) {
    // The running motion goes on: report the refusal once, leave the motion's own status alone.
    arm_state_t once = state();
    once.motion = arm_state_t::MOTION_REFUSED;
    once.command_seq = command.seq;
    once.last_error = reason;
    return once;
  }
  motion_ = arm_state_t::MOTION_REFUSED;
  command_seq_ = command.seq;
  last_error_ = reason;
  return state();
}

// ---- supervisor watchdog --------------------------------------------------------------------

bool ArmController::on_heartbeat(const heartbeat_t& heartbeat, int64_t utime) {
  if (heartbeat.service != "supervisor") return false;
  if (heartbeat.state == heartbeat_t::STATE_STOPPING) {
    if (!supervisor_problem_.empty()) return false;
    lose_supervisor("the supervisor is stopping");
    return true;
  }
  supervisor_seen_ = true;
  supervisor_last_ = utime;
  supervisor_problem_.clear();  // heard again: new commands are accepted (nothing restarts)
  return false;
}

std::optional<int64_t> ArmController::supervisor_deadline() const {
  if (!supervisor_seen_ || !supervisor_problem_.empty()) return std::nullopt;
  return supervisor_last_ + static_cast<int64_t>(std::llround(config_.supervisor_timeout * 1e6)) + 1;
}

bool ArmController::check_supervisor(int64_t utime) {
  const std::optional<int64_t> deadline = supervisor_deadline();
  if (!deadline || utime < *deadline) return false;
  lose_supervisor("supervisor heartbeat lost: none for " +
                  robot::format_number((utime - supervisor_last_) * 1e-6, 2) + " s (limit " +
                  robot::format_number(config_.supervisor_timeout, 2) + " s)");
  return true;
}

void ArmController::lose_supervisor(const std::string& reason) {
  supervisor_problem_ = reason;
  abort(reason);  // hold position whether or not anything was moving
}

// ---- reporting ------------------------------------------------------------------------------

arm_state_t ArmController::state() const {
  const robot::JointState joints = backend_.driver->read_joint_state();
  bus::ArmState s;
  s.utime = clock_;
  s.joints = joints.position;
  s.gripper_opening = joints.gripper_opening;
  s.gripper_measured = measured_gripper_;
  s.tool_in_world = config_.planner.base.to_world(robot::forward_kinematics(config_.planner.model, joints.position));
  s.motion = motion_;
  s.command_seq = command_seq_;
  s.last_error = last_error_;
  return bus::to_message(s);
}

std::string ArmController::describe() const {
  std::string text;
  switch (motion_) {
    case arm_state_t::MOTION_IDLE: text = "idle"; break;
    case arm_state_t::MOTION_MOVING: text = "moving: " + running_; break;
    case arm_state_t::MOTION_DONE: text = "done"; break;
    case arm_state_t::MOTION_REFUSED: text = "refused: " + last_error_; break;
    case arm_state_t::MOTION_STOPPED: text = "stopped: " + last_error_; break;
    default: text = "motion " + std::to_string(motion_); break;
  }
  if (command_seq_ >= 0) text += " (seq " + std::to_string(command_seq_) + ")";
  return text;
}

}  // namespace nudge::arm
