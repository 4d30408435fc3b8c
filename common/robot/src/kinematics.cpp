#include "nudge/robot/kinematics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nudge::robot {
namespace {

// Tolerance for "the same length" when testing reach limits and the table structure.
constexpr double kLengthEpsilon = 1e-12;
// Below this |sin(theta5)| the wrist angles cannot be separated numerically at all.
constexpr double kNumericalSingularity = 1e-12;
// Joint values this close outside a limit are clamped onto it (rounding, not a real violation).
constexpr double kLimitSlack = 1e-9;

// The lengths the closed-form solution uses: upper arm a2, shoulder offset d3, forearm d4.
struct PumaLengths {
  double a2;
  double d3;
  double d4;
};

bool near(double value, double expected) { return std::fabs(value - expected) < 1e-9; }

// The closed form below holds only for the PUMA shape of Table B.1; refuse anything else loudly
// rather than return wrong angles.
PumaLengths puma_lengths(const ArmModel& model) {
  const auto& l = model.links;
  const double alphas[kNumJoints] = {90, 0, -90, 90, -90, 0};
  bool puma_shape = true;
  for (int i = 0; i < kNumJoints; ++i) {
    puma_shape = puma_shape && near(l[i].alpha, deg_to_rad(alphas[i]));
    if (i != 1) puma_shape = puma_shape && near(l[i].a, 0.0);
    if (i != 2 && i != 3) puma_shape = puma_shape && near(l[i].d, 0.0);
  }
  puma_shape = puma_shape && l[1].a > 0 && l[3].d > 0;
  if (!puma_shape) {
    throw std::invalid_argument(
        "inverse kinematics: the arm model does not have the PUMA structure of Table B.1 "
        "(alpha = 90,0,-90,90,-90,0 deg; only a2, d3, d4 non-zero)");
  }
  return {l[1].a, l[2].d, l[3].d};
}

bool is_valid_pose(const Eigen::Isometry3d& pose) {
  if (!pose.matrix().allFinite()) return false;
  const Eigen::Matrix3d r = pose.linear();
  const bool orthonormal = (r.transpose() * r - Eigen::Matrix3d::Identity()).norm() < 1e-6;
  return orthonormal && r.determinant() > 0;
}

IkResult failure(IkFailure kind, std::string reason) {
  IkResult result;
  result.failure = kind;
  result.reason = std::move(reason);
  return result;
}

struct WristAngles {
  double theta4 = 0;
  double theta5 = 0;
  double theta6 = 0;
  double sin_theta5 = 0;  // |sin(theta5)|, how far from the wrist singularity
};

// Joints 4-6 from R36 = Rot_z(theta4) Rot_y(-theta5) Rot_z(theta6) (what links 4-6 of Table B.1
// multiply out to). The two branches differ by (theta4 + pi, -theta5, theta6 + pi); NoFlip keeps
// cos(theta4) >= 0.
WristAngles solve_wrist(const Eigen::Matrix3d& r36, WristFlip flip, double seed_theta4) {
  WristAngles w;
  const double sin5 = std::hypot(r36(0, 2), r36(1, 2));
  w.sin_theta5 = sin5;
  if (sin5 < kNumericalSingularity) {
    // Joints 4 and 6 turn about the same axis: only their sum (theta5 = 0) or difference
    // (theta5 = pi) is defined. Keep joint 4 where the seed has it so the wrist does not spin.
    w.theta4 = seed_theta4;
    if (r36(2, 2) > 0) {
      w.theta5 = 0;
      w.theta6 = std::atan2(r36(1, 0), r36(0, 0)) - w.theta4;
    } else {
      w.theta5 = kPi;
      w.theta6 = w.theta4 - std::atan2(-r36(1, 0), -r36(0, 0));
    }
    return w;
  }
  const bool positive_branch_has_no_flip = -r36(0, 2) >= 0;  // cos(theta4) of the sin5 > 0 branch
  const bool want_positive = (flip == WristFlip::NoFlip) == positive_branch_has_no_flip;
  if (want_positive) {
    w.theta4 = std::atan2(-r36(1, 2), -r36(0, 2));
    w.theta5 = std::atan2(sin5, r36(2, 2));
    w.theta6 = std::atan2(-r36(2, 1), r36(2, 0));
  } else {
    w.theta4 = std::atan2(r36(1, 2), r36(0, 2));
    w.theta5 = std::atan2(-sin5, r36(2, 2));
    w.theta6 = std::atan2(r36(2, 1), -r36(2, 0));
  }
  return w;
}

// Among theta + 2*pi*k, the value within [lower, upper] nearest the seed. False when none fits.
bool choose_alias(double theta, double lower, double upper, double seed, double* chosen) {
  const double base = wrap_angle(theta);
  bool found = false;
  double best_distance = std::numeric_limits<double>::infinity();
  for (int k = -2; k <= 2; ++k) {
    double candidate = base + 2.0 * kPi * k;
    if (candidate < lower - kLimitSlack || candidate > upper + kLimitSlack) continue;
    candidate = std::clamp(candidate, lower, upper);
    const double distance = std::fabs(candidate - seed);
    if (distance < best_distance) {
      best_distance = distance;
      *chosen = candidate;
      found = true;
    }
  }
  return found;
}

std::string joint_limit_reason(int joint, double theta, const JointLimits& limits,
                               const ArmConfiguration& configuration) {
  return "joint " + std::to_string(joint + 1) + " would be at " +
         format_number(rad_to_deg(wrap_angle(theta)), 1) + " deg, outside its limits [" +
         format_number(rad_to_deg(limits.lower[joint]), 1) + ", " +
         format_number(rad_to_deg(limits.upper[joint]), 1) + "] deg (" +
         to_string(configuration) + ")";
}

// Places raw angles within the joint limits (nearest alias to the seed), or explains which joint
// cannot be.
IkResult fit_into_limits(const JointVector& raw, const ArmModel& model, const IkOptions& options) {
  IkResult result;
  for (int j = 0; j < kNumJoints; ++j) {
    if (!choose_alias(raw[j], model.limits.lower[j], model.limits.upper[j], options.seed[j],
                      &result.q[j])) {
      return failure(IkFailure::JointLimit,
                     joint_limit_reason(j, raw[j], model.limits, options.configuration));
    }
  }
  return result;
}

}  // namespace

Eigen::Isometry3d dh_transform(const DhLink& link, double theta) {
  const double ct = std::cos(theta), st = std::sin(theta);
  const double ca = std::cos(link.alpha), sa = std::sin(link.alpha);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() << ct, -st * ca, st * sa,
                st, ct * ca, -ct * sa,
                0, sa, ca;
  t.translation() << link.a * ct, link.a * st, link.d;
  return t;
}

Eigen::Isometry3d flange_pose(const ArmModel& model, const JointVector& q) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < kNumJoints; ++i) t = t * dh_transform(model.links[i], q[i]);
  return t;
}

Eigen::Isometry3d forward_kinematics(const ArmModel& model, const JointVector& q) {
  return flange_pose(model, q) * model.tool;
}

ArmPoints arm_points(const ArmModel& model, const JointVector& q) {
  const Eigen::Isometry3d elbow =
      dh_transform(model.links[0], q[0]) * dh_transform(model.links[1], q[1]);
  const Eigen::Isometry3d flange = flange_pose(model, q);
  return {elbow.translation(), flange.translation(), (flange * model.tool).translation()};
}

std::vector<ArmConfiguration> all_configurations() {
  std::vector<ArmConfiguration> configurations;
  for (Shoulder s : {Shoulder::Right, Shoulder::Left})
    for (Elbow e : {Elbow::Up, Elbow::Down})
      for (WristFlip w : {WristFlip::NoFlip, WristFlip::Flip}) configurations.push_back({s, e, w});
  return configurations;
}

ArmConfiguration configuration_of(const ArmModel& model, const JointVector& q) {
  const PumaLengths l = puma_lengths(model);
  const double s23 = std::sin(q[1] + q[2]), c23 = std::cos(q[1] + q[2]);
  // Wrist centre in the arm plane: u along the horizontal reach direction, z up.
  const double u = l.a2 * std::cos(q[1]) - l.d4 * s23;
  const double z = l.a2 * std::sin(q[1]) + l.d4 * c23;
  // Sign of (wrist x elbow) in that plane: which side of the shoulder-wrist line the elbow is on.
  const double cross = u * l.a2 * std::sin(q[1]) - z * l.a2 * std::cos(q[1]);
  ArmConfiguration c;
  c.shoulder = u >= 0 ? Shoulder::Right : Shoulder::Left;
  c.elbow = (cross >= 0) == (u >= 0) ? Elbow::Up : Elbow::Down;
  c.wrist = std::cos(q[3]) >= 0 ? WristFlip::NoFlip : WristFlip::Flip;
  return c;
}

std::string to_string(const ArmConfiguration& c) {
  return std::string(c.shoulder == Shoulder::Right ? "right" : "left") + " arm, elbow " +
         (c.elbow == Elbow::Up ? "up" : "down") + ", wrist " +
         (c.wrist == WristFlip::NoFlip ? "no-flip" : "flip");
}

IkResult inverse_kinematics_flange(const ArmModel& model, const Eigen::Isometry3d& flange,
                                   const IkOptions& options) {
  const PumaLengths l = puma_lengths(model);
  if (!is_valid_pose(flange)) {
    return failure(IkFailure::InvalidPose,
                   "target pose has non-finite values or a non-orthonormal rotation");
  }
  const Eigen::Vector3d p = flange.translation();
  const ArmConfiguration& config = options.configuration;

  // Joint 1 (eq. B.4): the wrist centre must lie outside the cylinder of radius d3.
  const double r = std::hypot(p.x(), p.y());
  if (r < l.d3 - kLengthEpsilon) {
    return failure(IkFailure::InsideInnerRadius,
                   "wrist centre " + format_number(r) + " m from the joint 1 axis, inside the " +
                       format_number(l.d3) + " m shoulder offset");
  }
  const double phi = std::atan2(p.y(), p.x());
  const double delta = std::asin(std::min(1.0, l.d3 / r));
  const double theta1 = config.shoulder == Shoulder::Right ? phi + delta : phi + kPi - delta;
  const double c1 = std::cos(theta1), s1 = std::sin(theta1);

  // Joint 2 (eq. B.5): law of cosines in the arm plane; u = V114 of the thesis.
  const double u = p.x() * c1 + p.y() * s1;
  const double rho = std::hypot(u, p.z());
  if (rho > l.a2 + l.d4 + kLengthEpsilon) {
    return failure(IkFailure::OutOfReach,
                   "wrist centre " + format_number(rho) + " m from the shoulder, beyond the " +
                       format_number(l.a2 + l.d4) + " m reach of the arm");
  }
  if (rho < std::fabs(l.a2 - l.d4) - kLengthEpsilon || rho < 1e-9) {
    return failure(IkFailure::InsideInnerRadius,
                   "wrist centre " + format_number(rho) +
                       " m from the shoulder, too close for the arm to fold");
  }
  const double cos_psi =
      std::clamp((l.a2 * l.a2 - l.d4 * l.d4 + rho * rho) / (2.0 * l.a2 * rho), -1.0, 1.0);
  const double psi = std::acos(cos_psi);
  const double arm_sign = config.shoulder == Shoulder::Right ? 1.0 : -1.0;
  const double elbow_sign = config.elbow == Elbow::Up ? 1.0 : -1.0;
  const double theta2 = std::atan2(p.z(), u) + arm_sign * elbow_sign * psi;

  // Joint 3 (eq. B.6, with the sign that matches eq. B.1-B.2; see docs/robot.md).
  const double c2 = std::cos(theta2), s2 = std::sin(theta2);
  const double theta3 = std::atan2(l.a2 - (u * c2 + p.z() * s2), p.z() * c2 - u * s2);

  // Joints 4-6 (eq. B.7-B.9): the wrist rotation left after the first three joints.
  const Eigen::Matrix3d r03 = (dh_transform(model.links[0], theta1) *
                               dh_transform(model.links[1], theta2) *
                               dh_transform(model.links[2], theta3))
                                  .linear();
  const WristAngles wrist =
      solve_wrist(r03.transpose() * flange.linear(), config.wrist, options.seed[3]);

  JointVector raw;
  raw << theta1, theta2, theta3, wrist.theta4, wrist.theta5, wrist.theta6;
  IkResult result = fit_into_limits(raw, model, options);
  if (!result.ok()) return result;
  result.wrist_singular = wrist.sin_theta5 < options.wrist_singularity_tolerance;
  if (result.wrist_singular && options.refuse_wrist_singularity) {
    return failure(IkFailure::WristSingular,
                   "wrist singular: joint 5 at " + format_number(rad_to_deg(result.q[4]), 2) +
                       " deg leaves joints 4 and 6 aligned");
  }
  if (!result.q.allFinite()) {  // defensive: the steps above are all bounded
    return failure(IkFailure::InvalidPose, "inverse kinematics produced non-finite angles");
  }
  return result;
}

IkResult inverse_kinematics(const ArmModel& model, const Eigen::Isometry3d& tool_pose,
                            const IkOptions& options) {
  return inverse_kinematics_flange(model, tool_pose * model.tool.inverse(), options);
}

std::vector<JointVector> all_inverse_kinematics(const ArmModel& model,
                                                const Eigen::Isometry3d& tool_pose,
                                                const JointVector& seed) {
  std::vector<JointVector> solutions;
  IkOptions options;
  options.seed = seed;
  for (const ArmConfiguration& configuration : all_configurations()) {
    options.configuration = configuration;
    const IkResult result = inverse_kinematics(model, tool_pose, options);
    if (result.ok()) solutions.push_back(result.q);
  }
  return solutions;
}

IkResult nearest_inverse_kinematics(const ArmModel& model, const Eigen::Isometry3d& tool_pose,
                                    const JointVector& seed) {
  IkOptions options;
  options.seed = seed;
  // The seed's own configuration first: changing configuration swings the whole arm, however
  // close the two solutions look joint by joint.
  options.configuration = configuration_of(model, seed);
  const IkResult same = inverse_kinematics(model, tool_pose, options);
  if (same.ok() || same.failure != IkFailure::JointLimit) {
    return same;  // geometric failures are the same in every configuration
  }
  IkResult best = same;
  double best_distance = std::numeric_limits<double>::infinity();
  for (const ArmConfiguration& configuration : all_configurations()) {
    options.configuration = configuration;
    const IkResult candidate = inverse_kinematics(model, tool_pose, options);
    if (!candidate.ok()) continue;
    const double distance = joint_distance(candidate.q, seed);
    if (distance < best_distance) {
      best_distance = distance;
      best = candidate;
    }
  }
  if (!best.ok()) {
    return failure(IkFailure::JointLimit,
                   "no arm configuration keeps the joints within their limits; " + same.reason);
  }
  return best;
}

double joint_distance(const JointVector& a, const JointVector& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

}  // namespace nudge::robot
