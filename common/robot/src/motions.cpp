#include "nudge/robot/motions.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nudge::robot {
namespace {

// Consecutive IK solutions a few millimetres apart differ by a few degrees at most; a larger
// jump means the line passes a singularity or a configuration change, which would swing the arm.
constexpr double kMaxJointJumpPerStep = deg_to_rad(20.0);

// The nudging pad's top edge above the tool point (a 30 mm tall sponge centred on it, with room).
constexpr double kPadTopAboveToolPoint = 0.03;

std::string format_point(const Eigen::Vector3d& p) {
  return "(" + format_number(p.x()) + ", " + format_number(p.y()) + ", " + format_number(p.z()) +
         ") m";
}

// Appends `path` to `out`, leaving out its first waypoint (already the last of `out`).
void append_without_first(std::vector<JointVector>* out, const std::vector<JointVector>& path) {
  out->insert(out->end(), path.begin() + 1, path.end());
}

// Why consecutive solutions along a line are far apart: a joint that turns almost a full circle
// has wrapped around at its limit; anything else is a singularity or configuration change.
std::string jump_reason(const JointVector& previous, const JointVector& next) {
  int joint = 0;
  (next - previous).cwiseAbs().maxCoeff(&joint);
  const double jump = rad_to_deg(std::fabs(next[joint] - previous[joint]));
  const std::string which =
      "joint " + std::to_string(joint + 1) + " jumps by " + format_number(jump, 1) + " deg ";
  if (jump > 300.0) return which + "(it would pass its limit)";
  return which + "(the line passes a singularity)";
}

// The start configuration and, when joint 6 allows, the same pose with joint 6 turned a full
// circle either way: the extra range lets a wrist that runs into its limit start on the other side.
std::vector<JointVector> joint6_alternatives(const ArmModel& model, const JointVector& q) {
  std::vector<JointVector> alternatives{q};
  for (double turn : {-2.0 * kPi, 2.0 * kPi}) {
    JointVector other = q;
    other[5] += turn;
    if (other[5] >= model.limits.lower[5] && other[5] <= model.limits.upper[5]) {
      alternatives.push_back(other);
    }
  }
  return alternatives;
}

std::vector<JointVector> reversed(const std::vector<JointVector>& path) {
  return {path.rbegin(), path.rend()};
}

Eigen::Vector3d on_table(const Eigen::Vector3d& point, const SafetyConfig& safety, double height) {
  return {point.x(), point.y(), safety.table_z + height};
}

void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

}  // namespace

Eigen::Matrix3d tool_down_orientation(double yaw) {
  const Eigen::Vector3d x(std::cos(yaw), std::sin(yaw), 0.0);
  const Eigen::Vector3d z(0.0, 0.0, -1.0);
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

Eigen::Isometry3d tool_down_pose(const Eigen::Vector3d& point, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = tool_down_orientation(yaw);
  pose.translation() = point;
  return pose;
}

Eigen::Matrix3d tool_push_orientation(const Eigen::Vector3d& direction, const Eigen::Vector3d& lean,
                                      double tilt) {
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d z = -std::cos(tilt) * up + std::sin(tilt) * lean;
  // x = direction + b * up with x . z = 0: its horizontal part stays along the push.
  const double b = std::sin(tilt) * direction.dot(lean) / std::cos(tilt);
  const Eigen::Vector3d x = (direction + b * up).normalized();
  Eigen::Matrix3d r;
  r.col(0) = x;
  r.col(1) = z.cross(x);
  r.col(2) = z;
  return r;
}

JointPath cartesian_line(const ArmModel& model, const Eigen::Isometry3d& from,
                         const Eigen::Isometry3d& to, const JointVector& start, double step) {
  JointPath path;
  path.waypoints.push_back(start);
  const Eigen::Vector3d a = from.translation(), b = to.translation();
  const double length = (b - a).norm();
  if (!std::isfinite(length) || !start.allFinite()) {
    path.reason = "line has non-finite end points";
    return path;
  }
  const int steps = step > 0 ? std::max(1, static_cast<int>(std::ceil(length / step))) : 1;
  const Eigen::Quaterniond qa(from.linear()), qb(to.linear());
  // Stay in the start's configuration: switching (elbow up to down, say) mid-line would swing
  // the arm through the workspace between two nearby poses.
  IkOptions options;
  options.configuration = configuration_of(model, start);
  for (int k = 1; k <= steps; ++k) {
    const double fraction = static_cast<double>(k) / steps;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = qa.slerp(fraction, qb).toRotationMatrix();
    pose.translation() = a + fraction * (b - a);
    const JointVector& previous = path.waypoints.back();
    options.seed = previous;
    const IkResult solution = inverse_kinematics(model, pose, options);
    const std::string where = "at " + format_point(pose.translation()) + " on the line to " +
                              format_point(b) + ": ";
    if (!solution.ok()) {
      path.reason = where + solution.reason;
      return path;
    }
    if (steps > 1 && joint_distance(solution.q, previous) > kMaxJointJumpPerStep) {
      path.reason = where + jump_reason(previous, solution.q);
      return path;
    }
    path.waypoints.push_back(solution.q);
  }
  return path;
}

NudgeParams nudge_params_for_objects(double largest_radius, double smallest_radius,
                                     double tallest_height, double clearance, double overshoot,
                                     double above_tallest) {
  require(std::isfinite(largest_radius) && std::isfinite(smallest_radius) &&
              std::isfinite(tallest_height) && std::isfinite(clearance) &&
              std::isfinite(overshoot) && std::isfinite(above_tallest),
          "nudge params: object sizes must be finite");
  require(smallest_radius > overshoot,
          "nudge params: smallest_radius must exceed the overshoot, or P2 would cross the axis");
  require(largest_radius >= smallest_radius,
          "nudge params: largest_radius must not be smaller than smallest_radius");
  NudgeParams params;
  params.start_distance = largest_radius + clearance;
  params.stop_distance = smallest_radius - overshoot;
  params.approach_height = tallest_height + above_tallest;
  validate(params);
  return params;
}

void validate(const NudgeParams& p) {
  require(std::isfinite(p.approach_height) && std::isfinite(p.push_height) &&
              std::isfinite(p.start_distance) && std::isfinite(p.stop_distance) &&
              std::isfinite(p.cartesian_step),
          "nudge params: all fields must be finite");
  require(p.push_height >= 0, "nudge params: push_height must not be negative");
  require(p.approach_height > p.push_height,
          "nudge params: approach_height must be above push_height");
  require(p.stop_distance > 0,
          "nudge params: stop_distance must be positive (P2 never crosses the symmetry axis)");
  require(p.start_distance > p.stop_distance,
          "nudge params: start_distance must be larger than stop_distance");
  require(p.cartesian_step >= 0, "nudge params: cartesian_step must not be negative");
  require(std::isfinite(p.tool_tilt) && p.tool_tilt >= 0 && p.tool_tilt <= deg_to_rad(60.0),
          "nudge params: tool_tilt must lie in [0, 60] deg");
  require(std::isfinite(p.object_height) && std::isfinite(p.object_radius) &&
              std::isfinite(p.link_clearance) && std::isfinite(p.pad_front) &&
              p.object_height >= 0 && p.object_radius >= 0 && p.link_clearance >= 0 && p.pad_front >= 0,
          "nudge params: object_height, object_radius, link_clearance and pad_front must be finite and not negative");
}

double link_gap_to_pushed_object(const ArmModel& model, const SafetyConfig& safety,
                                 const NudgeParams& params, const Eigen::Vector3d& target,
                                 const Eigen::Vector3d& direction, const JointVector& q) {
  // The capsules end at the wrist centre and the tool point: no second forward kinematics.
  const ArmCapsules links = arm_capsules(model, safety, q);
  const Eigen::Vector3d& wrist = links.tool.a;
  const Eigen::Vector3d& tool_point = links.tool.b;
  // The object stands at the target until the pad's face reaches it, then goes along ahead of it.
  const double ahead = (tool_point - target).dot(direction) + params.pad_front + params.object_radius;
  const Eigen::Vector3d axis = target + std::max(0.0, ahead) * direction;
  // From above the pad to the object's top: the pad itself touches the object by design.
  const Eigen::Vector3d bottom(axis.x(), axis.y(), safety.table_z + params.push_height + kPadTopAboveToolPoint);
  const Eigen::Vector3d top(axis.x(), axis.y(), safety.table_z + params.object_height);
  if (top.z() <= bottom.z()) return std::numeric_limits<double>::infinity();
  double gap = std::numeric_limits<double>::infinity();
  for (const Capsule& c : {links.upper_arm, links.forearm}) {
    gap = std::min(gap, segment_distance(c.a, c.b, bottom, top) - c.radius);
  }
  gap = std::min(gap, segment_distance(wrist, wrist, bottom, top) - safety.forearm_radius);
  return gap - params.object_radius;
}

namespace {

// The first waypoint of `path` where a link comes within params.link_clearance of the pushed
// object, as a reason; "" when none does.
std::string link_clearance_problem(const ArmModel& model, const SafetyConfig& safety,
                                   const NudgeParams& params, const Eigen::Vector3d& target,
                                   const Eigen::Vector3d& direction,
                                   const std::vector<JointVector>& path) {
  if (params.object_height <= 0) return "";
  for (const JointVector& q : path) {
    const double gap = link_gap_to_pushed_object(model, safety, params, target, direction, q);
    if (gap < params.link_clearance) {
      return "the forearm or wrist would come within " + format_number(std::max(0.0, gap), 3) +
             " m of the object (" + format_number(params.object_height, 3) + " m tall, " +
             format_number(params.object_radius, 3) + " m radius)";
    }
  }
  return "";
}

// Fills plan->waypoints and plan->key_joints for plan->poses starting from q0 at P0 and checks
// the path; returns why it cannot, or "".
std::string plan_nudge_path(const ArmModel& model, const SafetyConfig& safety,
                            const NudgeParams& params, const Eigen::Vector3d& target,
                            const JointVector& q0, NudgePlan* plan) {
  const JointPath down =
      cartesian_line(model, plan->poses[0], plan->poses[1], q0, params.cartesian_step);
  if (!down.ok()) return "nudge P0->P1: " + down.reason;
  // Each line's clearance is checked as soon as it is solved: a lean that fails costs no more.
  std::string clash = link_clearance_problem(model, safety, params, target, plan->direction, down.waypoints);
  if (!clash.empty()) return "nudge P0->P1: " + clash;
  const JointPath push = cartesian_line(model, plan->poses[1], plan->poses[2],
                                        down.waypoints.back(), params.cartesian_step);
  if (!push.ok()) return "nudge P1->P2: " + push.reason;
  clash = link_clearance_problem(model, safety, params, target, plan->direction, push.waypoints);
  if (!clash.empty()) return "nudge P1->P2: " + clash;
  // Retrace the way out exactly: P2 -> P1 -> P0 (going straight from P2 to P0 toppled objects).
  plan->waypoints = down.waypoints;
  append_without_first(&plan->waypoints, push.waypoints);
  append_without_first(&plan->waypoints, reversed(push.waypoints));
  append_without_first(&plan->waypoints, reversed(down.waypoints));
  const JointVector q1 = down.waypoints.back(), q2 = push.waypoints.back();
  plan->key_joints = {q0, q1, q2, q1, q0};
  const CheckResult safe = check_joint_path(model, safety, plan->waypoints);
  return safe.ok() ? "" : "nudge path: " + safe.reason;
}

// The nudge with the tool at one lean (plan->tilt, plan->lean): "" or why not.
std::string plan_nudge_with_lean(const ArmModel& model, const SafetyConfig& safety,
                                 const Eigen::Vector3d& target, const NudgeParams& params,
                                 const JointVector& seed, NudgePlan* plan) {
  const Eigen::Vector3d& d = plan->direction;
  const Eigen::Vector3d p0 = on_table(target, safety, params.approach_height) - params.start_distance * d;
  const Eigen::Vector3d p1 = on_table(target, safety, params.push_height) - params.start_distance * d;
  const Eigen::Vector3d p2 = on_table(target, safety, params.push_height) - params.stop_distance * d;
  auto pose_at = [&](const Eigen::Vector3d& point) {
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
    pose.linear() = tool_push_orientation(d, plan->lean, plan->tilt);
    pose.translation() = point;
    return pose;
  };
  plan->poses = {pose_at(p0), pose_at(p1), pose_at(p2), pose_at(p1), pose_at(p0)};
  const IkResult start = safe_inverse_kinematics(model, safety, plan->poses[0], seed);
  if (!start.ok()) return "nudge P0: " + start.reason;
  // The arm goes from the seed (where it is) to P0 in a straight joint line. When P0 takes another
  // configuration (a left arm for a right one, where a leaned tool puts joint 5 past its limit),
  // that line can swing the tool out of the workspace ring: then another lean or direction is
  // tried rather than a nudge the arm would refuse (13% of the pushes across the ring did so).
  const CheckResult move = check_joint_path(model, safety, seed, start.q);
  if (!move.ok()) return "the move to P0: " + move.reason;
  std::string first_reason;
  for (const JointVector& q0 : joint6_alternatives(model, start.q)) {
    const std::string reason = plan_nudge_path(model, safety, params, target, q0, plan);
    if (reason.empty()) return "";
    if (first_reason.empty()) first_reason = reason;
  }
  return first_reason;
}

}  // namespace

NudgePlan plan_nudge(const ArmModel& model, const SafetyConfig& safety,
                     const Eigen::Vector3d& target, const Eigen::Vector3d& direction,
                     const NudgeParams& params, const JointVector& seed) {
  validate(params);
  validate(safety);
  NudgePlan plan;
  const Eigen::Vector3d horizontal(direction.x(), direction.y(), 0.0);
  if (!target.allFinite() || !horizontal.allFinite() || horizontal.norm() < 1e-9) {
    plan.reason = "nudge: target or push direction is not finite, or the direction is vertical";
    return plan;
  }
  const Eigen::Vector3d d = horizontal.normalized();
  plan.direction = d;
  if (safety.enforce_ring) {
    const CheckResult in_ring = check_workspace_ring(safety, on_table(target, safety, 0.0));
    if (!in_ring.ok()) {
      plan.reason = "nudge target: " + in_ring.reason;
      return plan;
    }
  }
  // Straight down first (the thesis' tool), then leaned: the wrist straight behind the pad, then
  // swung 45 and 90 degrees to either side of that.
  struct Lean {
    double tilt, swing_deg;
  };
  std::vector<Lean> leans{{0.0, 0.0}};
  if (params.tool_tilt > 0) {
    for (double swing : {0.0, 45.0, -45.0, 90.0, -90.0}) leans.push_back({params.tool_tilt, swing});
  }
  std::string first_reason;
  for (const Lean& lean : leans) {
    plan.tilt = lean.tilt;
    plan.lean = Eigen::AngleAxisd(deg_to_rad(lean.swing_deg), Eigen::Vector3d::UnitZ()) * d;
    const std::string reason = plan_nudge_with_lean(model, safety, target, params, seed, &plan);
    if (reason.empty()) {
      plan.reason.clear();
      return plan;
    }
    if (first_reason.empty()) first_reason = reason;
  }
  plan.reason = first_reason;
  return plan;
}

std::array<Eigen::Vector3d, 2> directions_across_view(const Eigen::Vector3d& camera_position,
                                                      const Eigen::Vector3d& target) {
  const Eigen::Vector3d ray = target - camera_position;
  Eigen::Vector3d across(-ray.y(), ray.x(), 0.0);
  if (!across.allFinite() || across.norm() < 1e-9) {
    across = Eigen::Vector3d::UnitX();  // camera straight above: any horizontal push is across
  }
  across.normalize();
  return {across, -across};
}

NudgePlan plan_nudge_across_view(const ArmModel& model, const SafetyConfig& safety,
                                 const Eigen::Vector3d& target,
                                 const Eigen::Vector3d& camera_position,
                                 const NudgeParams& params, const JointVector& seed) {
  std::array<Eigen::Vector3d, 2> candidates = directions_across_view(camera_position, target);
  // Try first the direction whose start point P1 lies nearer the middle of the ring: it leaves
  // the most room on both sides.
  const double middle = 0.5 * (safety.ring_inner + safety.ring_outer);
  auto off_middle = [&](const Eigen::Vector3d& d) {
    const Eigen::Vector3d p1 = target - params.start_distance * d;
    return std::fabs(std::hypot(p1.x(), p1.y()) - middle);
  };
  if (off_middle(candidates[1]) < off_middle(candidates[0])) {
    std::swap(candidates[0], candidates[1]);
  }
  NudgePlan first = plan_nudge(model, safety, target, candidates[0], params, seed);
  if (first.ok()) return first;
  NudgePlan second = plan_nudge(model, safety, target, candidates[1], params, seed);
  if (second.ok()) return second;
  second.reason = "neither push direction across the camera's view is safe: " + first.reason +
                  "; " + second.reason;
  return second;
}

GraspPlan plan_grasp(const ArmModel& model, const SafetyConfig& safety,
                     const Eigen::Vector3d& table_point, double grasp_height, double yaw,
                     const GraspParams& params, const JointVector& seed) {
  validate(safety);
  GraspPlan plan;
  if (!table_point.allFinite() || !std::isfinite(grasp_height) || !std::isfinite(yaw)) {
    plan.reason = "grasp: target, height or yaw is not finite";
    return plan;
  }
  const Eigen::Isometry3d above =
      tool_down_pose(on_table(table_point, safety, params.approach_height), yaw);
  const Eigen::Isometry3d at = tool_down_pose(on_table(table_point, safety, grasp_height), yaw);
  const Eigen::Isometry3d lifted =
      tool_down_pose(on_table(table_point, safety, params.lift_height), yaw);

  const IkResult start = safe_inverse_kinematics(model, safety, above, seed);
  if (!start.ok()) {
    plan.reason = "grasp approach: " + start.reason;
    return plan;
  }
  plan.above = start.q;
  JointPath descend = cartesian_line(model, above, at, start.q, params.cartesian_step);
  if (!descend.ok()) {
    plan.reason = "grasp descent: " + descend.reason;
    return plan;
  }
  JointPath lift =
      cartesian_line(model, at, lifted, descend.waypoints.back(), params.cartesian_step);
  if (!lift.ok()) {
    plan.reason = "grasp lift: " + lift.reason;
    return plan;
  }
  for (const auto& [what, path] : {std::pair{"grasp descent: ", &descend.waypoints},
                                   std::pair{"grasp lift: ", &lift.waypoints}}) {
    const CheckResult safe = check_joint_path(model, safety, *path);
    if (!safe.ok()) {
      plan.reason = what + safe.reason;
      return plan;
    }
  }
  plan.descend = std::move(descend.waypoints);
  plan.lift = std::move(lift.waypoints);
  return plan;
}

IkResult home_configuration(const ArmModel& model, const SafetyConfig& safety, double radius,
                            double height) {
  validate(safety);
  const Eigen::Isometry3d pose =
      tool_down_pose(Eigen::Vector3d(radius, 0.0, safety.table_z + height), 0.0);
  IkResult home = inverse_kinematics(model, pose);
  if (!home.ok()) return home;
  const CheckResult safe = check_configuration(model, safety, home.q);
  if (!safe.ok()) {
    home.failure = IkFailure::Unsafe;
    home.reason = "home pose: " + safe.reason;
  }
  return home;
}

IkResult rotate_wrist(const ArmModel& model, const JointVector& q, double angle) {
  IkResult result;
  result.q = q;
  result.q[5] += angle;
  const CheckResult limits = check_joint_limits(model, result.q);
  if (!limits.ok()) {
    result.failure = IkFailure::JointLimit;
    result.reason = "wrist rotation by " + format_number(rad_to_deg(angle), 1) + " deg: " +
                    limits.reason;
    result.q = q;
  }
  return result;
}

}  // namespace nudge::robot
