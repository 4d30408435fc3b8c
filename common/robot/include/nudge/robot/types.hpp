#pragma once
// Small vocabulary shared by the robot library: joint vectors, angle units and check outcomes.
//
// Units everywhere: metres, radians, seconds. Degrees only appear in human-readable reasons.
#include <Eigen/Core>

#include <string>
#include <utility>

namespace nudge::robot {

constexpr int kNumJoints = 6;
using JointVector = Eigen::Matrix<double, kNumJoints, 1>;

constexpr double kPi = 3.14159265358979323846;
constexpr double deg_to_rad(double degrees) { return degrees * kPi / 180.0; }
constexpr double rad_to_deg(double radians) { return radians * 180.0 / kPi; }

// Wraps an angle into (-pi, pi].
double wrap_angle(double radians);

// Joint vector from six values in degrees (tests and configuration files think in degrees).
JointVector joints_from_degrees(double j1, double j2, double j3, double j4, double j5, double j6);

// The outcome of a check: passed, or failed with a reason a person can act on
// ("tool point 0.372 m from the base axis, outside the 0.150-0.350 m workspace ring").
struct CheckResult {
  std::string reason;  // empty when the check passed

  bool ok() const { return reason.empty(); }
  static CheckResult pass() { return {}; }
  static CheckResult fail(std::string why) { return {std::move(why)}; }
};

// Formats a number with a fixed number of decimals for reasons ("0.372").
std::string format_number(double value, int decimals = 3);

}  // namespace nudge::robot
