#include "nudge/robot/safety.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace nudge::robot {
namespace {

// The samples of the straight joint line from `from` to `to` with no joint moving more than
// `step` between two (`from` only with include_from; `to` exactly), each with its fraction of the
// line, until `visit` returns false. A non-finite line is visited at `to` only.
template <class Visit>
void visit_joint_line(const JointVector& from, const JointVector& to, double step, bool include_from, Visit&& visit) {
  const double largest_change = (to - from).cwiseAbs().maxCoeff();
  const int steps = std::isfinite(largest_change) ? std::max(1, static_cast<int>(std::ceil(largest_change / step))) : 1;
  for (int k = include_from ? 0 : 1; k <= steps; ++k) {
    const double fraction = static_cast<double>(k) / steps;
    if (!visit(k == steps ? to : JointVector(from + fraction * (to - from)), fraction)) return;
  }
}

CheckResult check_above_table(const char* what, const Eigen::Vector3d& point,
                              const SafetyConfig& config) {
  const double lowest = config.table_z + config.table_margin;
  if (point.z() >= lowest) return CheckResult::pass();
  return CheckResult::fail(std::string(what) + " at z = " + format_number(point.z(), 4) +
                           " m, below the table clearance limit " + format_number(lowest, 4) +
                           " m (table at " + format_number(config.table_z) + " m + " +
                           format_number(config.table_margin) + " m margin)");
}

}  // namespace

void validate(const SafetyConfig& config) {
  auto require = [](bool ok, const char* message) {
    if (!ok) throw std::invalid_argument(std::string("safety config: ") + message);
  };
  require(std::isfinite(config.table_z), "table_z must be finite");
  require(std::isfinite(config.table_margin) && config.table_margin >= 0,
          "table_margin must be finite and non-negative");
  require(std::isfinite(config.ring_inner) && config.ring_inner >= 0,
          "ring_inner must be finite and non-negative");
  require(std::isfinite(config.ring_outer) && config.ring_outer > config.ring_inner,
          "ring_outer must be finite and larger than ring_inner");
  require(std::isfinite(config.path_step) && config.path_step > 0,
          "path_step must be finite and positive");
  for (double r : {config.pedestal_radius, config.upper_arm_radius, config.forearm_radius, config.tool_radius,
                   config.self_clearance})
    require(std::isfinite(r) && r >= 0, "link radii and self_clearance must be finite and non-negative");
}

double segment_distance(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                        const Eigen::Vector3d& b1) {
  // Closest points of two segments (Ericson, Real-Time Collision Detection, sec. 5.1.9).
  const Eigen::Vector3d d1 = a1 - a0, d2 = b1 - b0, r = a0 - b0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr double kTiny = 1e-18;
  double s = 0, t = 0;
  if (a <= kTiny && e <= kTiny) return r.norm();
  if (a <= kTiny) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kTiny) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > kTiny ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0) {
        t = 0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1) {
        t = 1;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((a0 + s * d1) - (b0 + t * d2)).norm();
}

ArmCapsules arm_capsules(const ArmModel& model, const SafetyConfig& config, const JointVector& q) {
  const Eigen::Isometry3d t1 = dh_transform(model.links[0], q[0]);
  const Eigen::Isometry3d t2 = t1 * dh_transform(model.links[1], q[1]);
  const Eigen::Isometry3d t3 = t2 * dh_transform(model.links[2], q[2]);
  const ArmPoints points = arm_points(model, q);
  // The shoulder offset d3 runs along the (parallel) joint 2 and 3 axes: the upper arm lies beside
  // the base axis, from the shoulder to the forearm's root (DH frame 3's origin).
  const Eigen::Vector3d offset = t3.translation() - t2.translation();
  ArmCapsules c;
  c.pedestal = {Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, config.table_z), config.pedestal_radius};
  c.upper_arm = {t1.translation() + offset, t3.translation(), config.upper_arm_radius};
  c.forearm = {t3.translation(), points.wrist, config.forearm_radius};
  c.tool = {points.wrist, points.tool, config.tool_radius};
  return c;
}

double link_gap_to_standing_object(const ArmModel& model, const SafetyConfig& config, const StandingObject& object,
                                   const JointVector& q) {
  const ArmCapsules c = arm_capsules(model, config, q);
  const Eigen::Vector3d bottom(object.place.x(), object.place.y(), config.table_z);
  const Eigen::Vector3d top(object.place.x(), object.place.y(), config.table_z + std::max(0.0, object.height));
  double gap = std::numeric_limits<double>::infinity();
  for (const Capsule* link : {&c.upper_arm, &c.forearm, &c.tool})
    gap = std::min(gap, segment_distance(link->a, link->b, bottom, top) - link->radius);
  return gap - object.radius;
}

double least_link_gap_along(const ArmModel& model, const SafetyConfig& config, const StandingObject& object,
                            const std::vector<JointVector>& waypoints) {
  double least = std::numeric_limits<double>::infinity();
  auto visit = [&](const JointVector& q, double) {
    least = std::min(least, link_gap_to_standing_object(model, config, object, q));
    return true;
  };
  for (size_t i = 0; i < waypoints.size(); ++i) {
    // Each segment's start is the previous one's end: only the first waypoint is visited alone.
    if (i == 0) visit(waypoints[0], 0.0);
    else visit_joint_line(waypoints[i - 1], waypoints[i], config.path_step, false, visit);
  }
  return least;
}

CheckResult check_self_collision(const ArmModel& model, const SafetyConfig& config, const JointVector& q) {
  if (!config.check_self_collision) return CheckResult::pass();
  const ArmCapsules c = arm_capsules(model, config, q);
  struct Pair {
    const char* first;
    const Capsule& a;
    const char* second;
    const Capsule& b;
  };
  for (const Pair& p : {Pair{"forearm", c.forearm, "pedestal", c.pedestal}, Pair{"tool", c.tool, "pedestal", c.pedestal},
                        Pair{"tool", c.tool, "upper arm", c.upper_arm}}) {
    const double gap = segment_distance(p.a.a, p.a.b, p.b.a, p.b.b) - p.a.radius - p.b.radius;
    if (gap < config.self_clearance) {
      return CheckResult::fail(std::string("self-collision: the ") + p.first + " comes within " +
                               format_number(std::max(0.0, gap), 3) + " m of the " + p.second + " (" +
                               format_number(config.self_clearance, 3) + " m required)");
    }
  }
  return CheckResult::pass();
}

CheckResult check_joint_limits(const ArmModel& model, const JointVector& q) {
  for (int j = 0; j < kNumJoints; ++j) {
    if (!std::isfinite(q[j])) {
      return CheckResult::fail("joint " + std::to_string(j + 1) + " is not a finite number");
    }
    if (q[j] < model.limits.lower[j] || q[j] > model.limits.upper[j]) {
      return CheckResult::fail("joint " + std::to_string(j + 1) + " at " +
                               format_number(rad_to_deg(q[j]), 1) + " deg, outside its limits [" +
                               format_number(rad_to_deg(model.limits.lower[j]), 1) + ", " +
                               format_number(rad_to_deg(model.limits.upper[j]), 1) + "] deg");
    }
  }
  return CheckResult::pass();
}

CheckResult check_workspace_ring(const SafetyConfig& config, const Eigen::Vector3d& tool_point) {
  const double radius = std::hypot(tool_point.x(), tool_point.y());
  if (radius >= config.ring_inner && radius <= config.ring_outer) return CheckResult::pass();
  return CheckResult::fail("tool point " + format_number(radius) +
                           " m from the base axis, outside the " +
                           format_number(config.ring_inner) + "-" +
                           format_number(config.ring_outer) + " m workspace ring");
}

CheckResult check_table_clearance(const ArmModel& model, const SafetyConfig& config,
                                  const JointVector& q) {
  const ArmPoints points = arm_points(model, q);
  for (const auto& [what, point] : {std::pair{"tool point", points.tool},
                                    std::pair{"wrist centre", points.wrist},
                                    std::pair{"elbow", points.elbow}}) {
    CheckResult result = check_above_table(what, point, config);
    if (!result.ok()) return result;
  }
  return CheckResult::pass();
}

CheckResult check_configuration(const ArmModel& model, const SafetyConfig& config,
                                const JointVector& q) {
  CheckResult result = check_joint_limits(model, q);
  if (!result.ok()) return result;
  result = check_table_clearance(model, config, q);
  if (!result.ok()) return result;
  result = check_self_collision(model, config, q);
  if (!result.ok() || !config.enforce_ring) return result;
  return check_workspace_ring(config, forward_kinematics(model, q).translation());
}

CheckResult check_joint_path(const ArmModel& model, const SafetyConfig& config,
                             const JointVector& from, const JointVector& to) {
  validate(config);
  if (!std::isfinite((to - from).cwiseAbs().maxCoeff())) {
    return CheckResult::fail("path has non-finite joint values");
  }
  CheckResult unsafe = CheckResult::pass();
  visit_joint_line(from, to, config.path_step, true, [&](const JointVector& q, double fraction) {
    CheckResult result = check_configuration(model, config, q);
    if (!result.ok()) {
      unsafe = CheckResult::fail("unsafe at " + format_number(100.0 * fraction, 1) + "% of the path: " + result.reason);
    }
    return result.ok();
  });
  return unsafe;
}

CheckResult check_joint_path(const ArmModel& model, const SafetyConfig& config,
                             const std::vector<JointVector>& waypoints) {
  if (waypoints.empty()) return CheckResult::fail("path has no waypoints");
  if (waypoints.size() == 1) return check_configuration(model, config, waypoints.front());
  for (size_t i = 1; i < waypoints.size(); ++i) {
    CheckResult result = check_joint_path(model, config, waypoints[i - 1], waypoints[i]);
    if (!result.ok()) {
      return CheckResult::fail("segment " + std::to_string(i) + " of " +
                               std::to_string(waypoints.size() - 1) + ": " + result.reason);
    }
  }
  return CheckResult::pass();
}

IkResult safe_inverse_kinematics(const ArmModel& model, const SafetyConfig& config,
                                 const Eigen::Isometry3d& tool_pose, const JointVector& seed) {
  const IkResult nearest = nearest_inverse_kinematics(model, tool_pose, seed);
  if (!nearest.ok()) return nearest;
  // The nearest solution may dip the elbow below the table while another configuration is
  // fine: then take the nearest safe one.
  IkResult best;
  best.failure = IkFailure::Unsafe;
  best.reason = check_configuration(model, config, nearest.q).reason;
  if (best.reason.empty()) return nearest;
  double best_distance = std::numeric_limits<double>::infinity();
  IkOptions options;
  options.seed = seed;
  for (const ArmConfiguration& configuration : all_configurations()) {
    options.configuration = configuration;
    const IkResult candidate = inverse_kinematics(model, tool_pose, options);
    if (!candidate.ok() || !check_configuration(model, config, candidate.q).ok()) continue;
    const double distance = joint_distance(candidate.q, seed);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  return best;
}

}  // namespace nudge::robot
