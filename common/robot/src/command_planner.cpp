#include "nudge/robot/command_planner.hpp"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "nudge/robot/kinematics.hpp"

namespace nudge::robot {

namespace {

// A path step must start where the previous one ended, to numerical precision.
constexpr double kContinuityTolerance = 1e-6;  // radians

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

// A field that 0 leaves at the configuration's default; negative or non-finite values are malformed.
bool override_with(double field, double* value) {
  if (!std::isfinite(field) || field < 0) return false;
  if (field > 0) *value = field;
  return true;
}

MotionPlan malformed(const std::string& why) {
  MotionPlan p;
  p.reason = why;
  p.malformed = true;
  return p;
}

MotionPlan refused(const std::string& why) {
  MotionPlan p;
  p.reason = why;
  return p;
}

MotionStep move_step(const JointVector& goal, std::string what, double scale) {
  MotionStep s;
  s.kind = MotionStep::Kind::Move;
  s.what = std::move(what);
  s.goal = goal;
  s.speed_scale = scale;
  return s;
}

MotionStep path_step(std::string what, std::vector<JointVector> path, double scale) {
  MotionStep s;
  s.kind = MotionStep::Kind::Path;
  s.what = std::move(what);
  s.path = std::move(path);
  s.speed_scale = scale;
  return s;
}

MotionStep gripper_step(MotionStep::Kind kind, std::string what) {
  MotionStep s;
  s.kind = kind;
  s.what = std::move(what);
  return s;
}

// The plan of `steps`, checked from `current` with `safety`.
MotionPlan checked(const ArmModel& model, const SafetyConfig& safety, std::vector<MotionStep> steps,
                   const JointVector& current) {
  MotionPlan p;
  p.steps = std::move(steps);
  p.reason = check_steps(model, safety, p.steps, current);
  return p;
}

// Everything a command needs while it is planned.
struct Planning {
  const PlannerConfig& config;
  const Command& command;
  const JointVector& current;
  SafetyConfig safety;  // the configuration's, on the base's table
  double scale = 1.0;   // the command's speed scale

  MotionPlan move_joints() const {
    if (command.joints.size() != static_cast<size_t>(kNumJoints)) {
      return malformed("needs 6 joints, got " + std::to_string(command.joints.size()));
    }
    JointVector goal;
    for (int j = 0; j < kNumJoints; ++j) goal[j] = command.joints[j];
    if (!goal.allFinite()) return malformed("joint values are not finite");
    return checked(config.model, safety, {move_step(goal, "the move to the joints", scale)}, current);
  }

  MotionPlan move_pose() const {
    Eigen::Isometry3d world_pose;
    if (!pose_from_parts(command.target_position, command.target_orientation, &world_pose)) {
      return malformed("target is not finite or its quaternion is not of unit length");
    }
    const IkResult ik = safe_inverse_kinematics(config.model, safety, config.base.to_base(world_pose), current);
    if (!ik.ok()) return refused(ik.reason);
    return checked(config.model, safety, {move_step(ik.q, "the move to the pose", scale)}, current);
  }

  MotionPlan nudge() const {
    NudgeParams params = config.nudge;
    if (!override_with(command.height, &params.push_height) ||
        !override_with(command.approach_height, &params.approach_height) ||
        !override_with(command.start_distance, &params.start_distance) ||
        !override_with(command.stop_distance, &params.stop_distance) ||
        !override_with(command.object_height, &params.object_height)) {
      return malformed("heights and distances must be finite and not negative");
    }
    if (!command.target_position.allFinite() || !command.direction.allFinite()) {
      return malformed("target or direction is not finite");
    }
    try {
      validate(params);
    } catch (const std::invalid_argument& e) {
      return refused(e.what());
    }
    const NudgePlan nudge = plan_nudge(config.model, safety, config.base.point_to_base(command.target_position),
                                       config.base.direction_to_base(command.direction), params, current);
    if (!nudge.ok()) return refused(nudge.reason);
    // The move to P0 first on its own, so that its reason is named before the nudge's.
    const MotionStep to_p0 = move_step(nudge.key_joints[0], "the move to P0", scale);
    const std::string p0_problem = check_steps(config.model, safety, {to_p0}, current);
    if (!p0_problem.empty()) return refused(p0_problem);
    return checked(config.model, safety, {to_p0, path_step("the nudge P0-P1-P2-P1-P0", nudge.waypoints, scale)},
                   current);
  }

  MotionPlan grasp_or_place() const {
    const bool grasp = command.kind == CommandKind::Grasp;
    if (!command.target_position.allFinite()) return malformed("target is not finite");
    if (!std::isfinite(command.height) || command.height <= 0) {
      return malformed("height (the tool point above the table) must be positive");
    }
    // The tool's x axis: the target orientation's x axis about the vertical (unset: world x).
    double world_yaw = 0.0;
    if (!command.target_orientation.isZero(0.0)) {
      Eigen::Isometry3d pose;
      if (!pose_from_parts(Eigen::Vector3d::Zero(), command.target_orientation, &pose)) {
        return malformed("target quaternion is not of unit length");
      }
      const Eigen::Vector3d x = pose.linear().col(0);
      if (std::hypot(x.x(), x.y()) > 1e-6) world_yaw = std::atan2(x.y(), x.x());
    }
    const GraspPlan g = plan_grasp(config.model, safety, config.base.point_to_base(command.target_position),
                                   command.height, world_yaw - config.base.yaw, config.grasp, current);
    if (!g.ok()) return refused(g.reason);
    const MotionStep above = move_step(g.above, "the move above the target", scale);
    const std::string above_problem = check_steps(config.model, safety, {above}, current);
    if (!above_problem.empty()) return refused(above_problem);
    std::vector<MotionStep> steps;
    if (grasp) steps.push_back(gripper_step(MotionStep::Kind::OpenGripper, "opening the gripper"));
    steps.push_back(above);
    steps.push_back(path_step("the descent", g.descend, scale));
    if (grasp) {
      steps.push_back(gripper_step(MotionStep::Kind::CloseGripper, "closing the gripper"));
      steps.push_back(path_step("the lift", g.lift, scale));
    } else {
      steps.push_back(gripper_step(MotionStep::Kind::OpenGripper, "opening the gripper"));
      steps.push_back(path_step("the way up", {g.descend.rbegin(), g.descend.rend()}, scale));
    }
    return checked(config.model, safety, std::move(steps), current);
  }

  MotionPlan rotate() const {
    if (!std::isfinite(command.angle)) return malformed("angle is not finite");
    const IkResult turned = rotate_wrist(config.model, current, command.angle);
    if (!turned.ok()) return refused(turned.reason);
    return checked(config.model, safety, {move_step(turned.q, "the wrist rotation", scale)}, current);
  }

  MotionPlan home() const {
    const IkResult home = home_configuration(config.model, safety, config.home_radius, config.home_height);
    if (!home.ok()) return refused(home.reason);
    // Parking must work from anywhere safe, also from a start pose outside the ring.
    SafetyConfig parking = safety;
    parking.enforce_ring = false;
    return checked(config.model, parking, {move_step(home.q, "the move home", scale)}, current);
  }
};

}  // namespace

PlannerConfig planner_config(const Workspace& workspace) {
  validate(workspace);
  PlannerConfig config;
  apply_workspace(workspace, &config.model);
  apply_workspace(workspace, &config.safety);
  config.base = BaseFrame::of(workspace);
  return config;
}

void validate(const PlannerConfig& c) {
  require(c.base.height > 0 && std::isfinite(c.base.height), "base height must be positive");
  require(std::isfinite(c.base.yaw), "base yaw must be finite");
  require(c.speed_scale >= kMinSpeedScale && c.speed_scale <= 1, "speed scale must lie in [0.01, 1]");
  require(std::isfinite(c.home_radius) && std::isfinite(c.home_height), "home radius and height must be finite");
  require(c.model.tool.translation().allFinite(), "tool must be finite");
  validate(c.nudge);
  SafetyConfig safety = c.safety;
  safety.table_z = c.base.table_z();
  validate(safety);
}

std::string command_name(CommandKind kind) {
  switch (kind) {
    case CommandKind::MoveJoints: return "move joints";
    case CommandKind::MovePose: return "move to pose";
    case CommandKind::Nudge: return "nudge";
    case CommandKind::Grasp: return "grasp";
    case CommandKind::Place: return "place";
    case CommandKind::OpenGripper: return "open gripper";
    case CommandKind::CloseGripper: return "close gripper";
    case CommandKind::RotateWrist: return "rotate wrist";
    case CommandKind::Home: return "home";
  }
  return "command";
}

MotionPlan plan_command(const PlannerConfig& config, const Command& command, const JointVector& current) {
  Planning planning{config, command, current, config.safety};
  planning.safety.table_z = config.base.table_z();
  planning.scale = config.speed_scale;
  if (!override_with(command.speed_scale, &planning.scale) || planning.scale > 1 ||
      planning.scale < kMinSpeedScale) {
    std::ostringstream why;
    why << "speed_scale " << command.speed_scale << " outside " << kMinSpeedScale << "..1 (0: the default)";
    return malformed(why.str());
  }
  switch (command.kind) {
    case CommandKind::MoveJoints: return planning.move_joints();
    case CommandKind::MovePose: return planning.move_pose();
    case CommandKind::Nudge: return planning.nudge();
    case CommandKind::Grasp:
    case CommandKind::Place: return planning.grasp_or_place();
    case CommandKind::OpenGripper:
      return checked(config.model, planning.safety, {gripper_step(MotionStep::Kind::OpenGripper, "opening the gripper")}, current);
    case CommandKind::CloseGripper:
      return checked(config.model, planning.safety, {gripper_step(MotionStep::Kind::CloseGripper, "closing the gripper")}, current);
    case CommandKind::RotateWrist: return planning.rotate();
    case CommandKind::Home: return planning.home();
  }
  return malformed("unknown command kind");
}

std::string check_steps(const ArmModel& model, const SafetyConfig& safety, const std::vector<MotionStep>& steps,
                        const JointVector& current) {
  JointVector at = current;
  for (const MotionStep& step : steps) {
    if (step.kind == MotionStep::Kind::Move) {
      const CheckResult goal = check_configuration(model, safety, step.goal);
      if (!goal.ok()) return step.what + " ends unsafe: " + goal.reason;
      const CheckResult line = check_joint_path(model, safety, at, step.goal);
      if (!line.ok()) return step.what + ": " + line.reason;
      at = step.goal;
    } else if (step.kind == MotionStep::Kind::Path) {
      if (step.path.empty()) return step.what + " has no waypoints";
      if (joint_distance(step.path.front(), at) > kContinuityTolerance) {
        return step.what + " does not start where the arm will be";
      }
      const CheckResult path = check_joint_path(model, safety, step.path);
      if (!path.ok()) return step.what + ": " + path.reason;
      at = step.path.back();
    }
  }
  return "";
}

bool pose_from_parts(const Eigen::Vector3d& position, const Eigen::Vector4d& wxyz, Eigen::Isometry3d* pose) {
  Eigen::Quaterniond q(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
  if (!position.allFinite() || !q.coeffs().allFinite() || std::fabs(q.norm() - 1.0) > 1e-3) return false;
  q.normalize();
  *pose = Eigen::Isometry3d::Identity();
  pose->linear() = q.toRotationMatrix();
  pose->translation() = position;
  return true;
}

}  // namespace nudge::robot
