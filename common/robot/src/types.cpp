#include "nudge/robot/types.hpp"

#include <cmath>
#include <iomanip>
#include <sstream>

namespace nudge::robot {

double wrap_angle(double radians) {
  double wrapped = std::remainder(radians, 2.0 * kPi);  // [-pi, pi]
  if (wrapped <= -kPi) wrapped += 2.0 * kPi;
  return wrapped;
}

JointVector joints_from_degrees(double j1, double j2, double j3, double j4, double j5, double j6) {
  JointVector q;
  q << deg_to_rad(j1), deg_to_rad(j2), deg_to_rad(j3), deg_to_rad(j4), deg_to_rad(j5),
      deg_to_rad(j6);
  return q;
}

std::string format_number(double value, int decimals) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(decimals) << value;
  return out.str();
}

}  // namespace nudge::robot
