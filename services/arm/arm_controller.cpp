#include "arm_controller.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "nudge/bus/arm_convert.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/trajectory.hpp"

namespace nudge::arm {

namespace {

using robot::JointVector;

// A path step must start where the previous one ended, to numerical precision.
constexpr double kContinuityTolerance = 1e-6;  // radians

constexpr double kMinSpeedScale = 0.01;

std::string command_name(int8_t code) {
  switch (code) {
    case arm_command_t::COMMAND_STOP: return "stop";
    case arm_command_t::COMMAND_MOVE_JOINTS: return "move joints";
    case arm_command_t::COMMAND_MOVE_POSE: return "move to pose";
    case arm_command_t::COMMAND_NUDGE: return "nudge";
    case arm_command_t::COMMAND_GRASP: return "grasp";
    case arm_command_t::COMMAND_OPEN: return "open gripper";
    case arm_command_t::COMMAND_CLOSE: return "close gripper";
    case arm_command_t::COMMAND_ROTATE_WRIST: return "rotate wrist";
    case arm_command_t::COMMAND_PLACE: return "place";
    case arm_command_t::COMMAND_HOME: return "home";
    default: return "command " + std::to_string(code);
  }
}

// A field that 0 leaves at the service's default; negative or non-finite values are malformed.
bool override_with(double field, double* value) {
  if (!std::isfinite(field) || field < 0) return false;
  if (field > 0) *value = field;
  return true;
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

}  // namespace

void validate(const ControllerConfig& c) {
  require(c.base.height > 0 && std::isfinite(c.base.height), "base height must be positive");
  require(std::isfinite(c.base.yaw), "base yaw must be finite");
  require(c.speed_scale >= kMinSpeedScale && c.speed_scale <= 1, "speed scale must lie in [0.01, 1]");
  require(c.period_utime > 0, "state period must be positive");
  require(c.supervisor_timeout > 0 && std::isfinite(c.supervisor_timeout),
          "supervisor timeout must be positive");
  require(std::isfinite(c.home_radius) && std::isfinite(c.home_height),
          "home radius and height must be finite");
  robot::validate(c.nudge);
  robot::SafetyConfig safety = c.safety;
  safety.table_z = c.base.table_z();
  robot::validate(safety);
}

ArmController::ArmController(ControllerConfig config, Backend backend)
    : config_(std::move(config)), backend_(std::move(backend)) {
  validate(config_);
  if (!backend_.driver || !backend_.advance) throw std::invalid_argument("backend without a driver");
  config_.safety.table_z = config_.base.table_z();
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
                                        step.speed_scale * config_.model.max_speed,
                                        step.speed_scale * config_.model.max_acceleration);
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
          robot::LinearTrajectory::at_speed(step.path, config_.model.max_speed, step.speed_scale);
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
  const JointVector current = backend_.driver->read_joint_state().position;
  Plan p = plan(command, current);
  if (!p.reason.empty()) return refuse(command, command_name(command.command) + ": " + p.reason, p.malformed);

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

ArmController::Plan ArmController::plan_move(const JointVector& goal, const std::string& what,
                                             double scale, const JointVector& current,
                                             const robot::SafetyConfig& safety) const {
  Plan p;
  Step step;
  step.kind = Step::Kind::Move;
  step.what = what;
  step.goal = goal;
  step.speed_scale = scale;
  p.steps.push_back(step);
  p.reason = check_steps(p.steps, current, safety);
  return p;
}

ArmController::Plan ArmController::plan(const arm_command_t& command,
                                        const JointVector& current) const {
  const robot::ArmModel& model = config_.model;
  const robot::SafetyConfig& safety = config_.safety;
  auto malformed = [](const std::string& why) {
    Plan p;
    p.reason = why;
    p.malformed = true;
    return p;
  };
  auto refused = [](const std::string& why) {
    Plan p;
    p.reason = why;
    return p;
  };
  auto path_step = [](Step::Kind kind, std::string what, std::vector<JointVector> path,
                      double scale) {
    Step s;
    s.kind = kind;
    s.what = std::move(what);
    s.path = std::move(path);
    s.speed_scale = scale;
    return s;
  };
  auto gripper_step = [](Step::Kind kind, std::string what) {
    Step s;
    s.kind = kind;
    s.what = std::move(what);
    return s;
  };

  // A floor on the speed keeps a tiny scale from asking for days of samples.
  double scale = config_.speed_scale;
  if (!override_with(command.speed_scale, &scale) || scale > 1 || scale < kMinSpeedScale) {
    std::ostringstream why;
    why << "speed_scale " << command.speed_scale << " outside " << kMinSpeedScale
        << "..1 (0: the service's default)";
    return malformed(why.str());
  }
  const Eigen::Vector3d target_position(command.target.position[0], command.target.position[1],
                                        command.target.position[2]);

  std::vector<Step> steps;
  robot::SafetyConfig checked_with = safety;
  switch (command.command) {
    case arm_command_t::COMMAND_MOVE_JOINTS: {
      if (command.num_joints != robot::kNumJoints || command.joints.size() != robot::kNumJoints) {
        return malformed("needs 6 joints, got " + std::to_string(command.num_joints));
      }
      JointVector goal;
      for (int j = 0; j < robot::kNumJoints; ++j) goal[j] = command.joints[j];
      if (!goal.allFinite()) return malformed("joint values are not finite");
      return plan_move(goal, "the move to the joints", scale, current, safety);
    }
    case arm_command_t::COMMAND_MOVE_POSE: {
      Eigen::Isometry3d world_pose;
      if (!bus::from_message(command.target, &world_pose)) {
        return malformed("target is not finite or its quaternion is not of unit length");
      }
      const robot::IkResult ik =
          robot::safe_inverse_kinematics(model, safety, config_.base.to_base(world_pose), current);
      if (!ik.ok()) return refused(ik.reason);
      return plan_move(ik.q, "the move to the pose", scale, current, safety);
    }
    case arm_command_t::COMMAND_NUDGE: {
      robot::NudgeParams params = config_.nudge;
      if (!override_with(command.height, &params.push_height) ||
          !override_with(command.approach_height, &params.approach_height) ||
          !override_with(command.start_distance, &params.start_distance) ||
          !override_with(command.stop_distance, &params.stop_distance)) {
        return malformed("heights and distances must be finite and not negative");
      }
      const Eigen::Vector3d direction(command.direction[0], command.direction[1],
                                      command.direction[2]);
      if (!target_position.allFinite() || !direction.allFinite()) {
        return malformed("target or direction is not finite");
      }
      try {
        robot::validate(params);
      } catch (const std::invalid_argument& e) {
        return refused(e.what());
      }
      const robot::NudgePlan nudge =
          robot::plan_nudge(model, safety, config_.base.point_to_base(target_position),
                            config_.base.direction_to_base(direction), params, current);
      if (!nudge.ok()) return refused(nudge.reason);
      Plan to_p0 = plan_move(nudge.key_joints[0], "the move to P0", scale, current, safety);
      if (!to_p0.reason.empty()) return to_p0;
      steps = std::move(to_p0.steps);
      steps.push_back(path_step(Step::Kind::Path, "the nudge P0-P1-P2-P1-P0", nudge.waypoints, scale));
      break;
    }
    case arm_command_t::COMMAND_GRASP:
    case arm_command_t::COMMAND_PLACE: {
      const bool grasp = command.command == arm_command_t::COMMAND_GRASP;
      if (!target_position.allFinite()) return malformed("target is not finite");
      if (!std::isfinite(command.height) || command.height <= 0) {
        return malformed("height (the tool point above the table) must be positive");
      }
      // The tool's x axis: the target orientation's x axis about the vertical (unset: world x).
      double world_yaw = 0.0;
      pose_t orientation_only{};
      std::copy(std::begin(command.target.orientation), std::end(command.target.orientation),
                std::begin(orientation_only.orientation));
      if (!bus::is_unset(orientation_only)) {
        Eigen::Isometry3d pose;
        if (!bus::from_message(orientation_only, &pose)) {
          return malformed("target quaternion is not of unit length");
        }
        const Eigen::Vector3d x = pose.linear().col(0);
        if (std::hypot(x.x(), x.y()) > 1e-6) world_yaw = std::atan2(x.y(), x.x());
      }
      const robot::GraspPlan g = robot::plan_grasp(
          model, safety, config_.base.point_to_base(target_position), command.height,
          world_yaw - config_.base.yaw, config_.grasp, current);
      if (!g.ok()) return refused(g.reason);
      if (grasp) steps.push_back(gripper_step(Step::Kind::OpenGripper, "opening the gripper"));
      Plan above = plan_move(g.above, "the move above the target", scale, current, safety);
      if (!above.reason.empty()) return above;
      steps.push_back(above.steps.front());
      steps.push_back(path_step(Step::Kind::Path, "the descent", g.descend, scale));
      if (grasp) {
        steps.push_back(gripper_step(Step::Kind::CloseGripper, "closing the gripper"));
        steps.push_back(path_step(Step::Kind::Path, "the lift", g.lift, scale));
      } else {
        steps.push_back(gripper_step(Step::Kind::OpenGripper, "opening the gripper"));
        steps.push_back(path_step(Step::Kind::Path, "the way up",
                                  {g.descend.rbegin(), g.descend.rend()}, scale));
      }
      break;
    }
    case arm_command_t::COMMAND_OPEN:
      steps.push_back(gripper_step(Step::Kind::OpenGripper, "opening the gripper"));
      break;
    case arm_command_t::COMMAND_CLOSE:
      steps.push_back(gripper_step(Step::Kind::CloseGripper, "closing the gripper"));
      break;
    case arm_command_t::COMMAND_ROTATE_WRIST: {
      if (!std::isfinite(command.angle)) return malformed("angle is not finite");
      const robot::IkResult turned = robot::rotate_wrist(model, current, command.angle);
      if (!turned.ok()) return refused(turned.reason);
      return plan_move(turned.q, "the wrist rotation", scale, current, safety);
    }
    case arm_command_t::COMMAND_HOME: {
      const robot::IkResult home =
          robot::home_configuration(model, safety, config_.home_radius, config_.home_height);
      if (!home.ok()) return refused(home.reason);
      // Parking must work from anywhere safe, also from a start pose outside the ring.
      checked_with.enforce_ring = false;
      return plan_move(home.q, "the move home", scale, current, checked_with);
    }
    default:
      return malformed("unknown command code " + std::to_string(command.command));
  }
  Plan p;
  p.steps = std::move(steps);
  p.reason = check_steps(p.steps, current, checked_with);
  return p;
}

std::string ArmController::check_steps(const std::vector<Step>& steps, const JointVector& current,
                                       const robot::SafetyConfig& safety) const {
  JointVector at = current;
  for (const Step& step : steps) {
    if (step.kind == Step::Kind::Move) {
      const robot::CheckResult goal = robot::check_configuration(config_.model, safety, step.goal);
      if (!goal.ok()) return step.what + " ends unsafe: " + goal.reason;
      const robot::CheckResult line = robot::check_joint_path(config_.model, safety, at, step.goal);
      if (!line.ok()) return step.what + ": " + line.reason;
      at = step.goal;
    } else if (step.kind == Step::Kind::Path) {
      if (step.path.empty()) return step.what + " has no waypoints";
      if (robot::joint_distance(step.path.front(), at) > kContinuityTolerance) {
        return step.what + " does not start where the arm will be";
      }
      const robot::CheckResult path = robot::check_joint_path(config_.model, safety, step.path);
      if (!path.ok()) return step.what + ": " + path.reason;
      at = step.path.back();
    }
  }
  return "";
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
  s.tool_in_world = config_.base.to_world(robot::forward_kinematics(config_.model, joints.position));
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
