#include "nudge/robot/puma260.hpp"

#include "nudge/robot/workspace.hpp"

namespace nudge::robot {

std::array<DhLink, kNumJoints> puma260_links() {
  return {{
      {deg_to_rad(90), 0.0, 0.0},
      {deg_to_rad(0), 0.2032, 0.0},
      {deg_to_rad(-90), 0.0, 0.12624},
      {deg_to_rad(90), 0.0, 0.2032},
      {deg_to_rad(-90), 0.0, 0.0},
      {deg_to_rad(0), 0.0, 0.0},
  }};
}

JointLimits puma260_limits() {
  JointLimits limits;
  limits.lower = joints_from_degrees(-160, -45, -225, -110, -100, -266);
  limits.upper = joints_from_degrees(160, 225, 45, 170, 100, 266);
  return limits;
}

JointVector puma260_max_speed() { return joints_from_degrees(45, 45, 45, 90, 90, 90); }

JointVector puma260_max_acceleration() { return joints_from_degrees(90, 90, 90, 180, 180, 180); }

Eigen::Isometry3d default_tool() {
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();
  tool.translation() = Eigen::Vector3d(0.0, 0.0, Workspace{}.tool_length);
  return tool;
}

ArmModel puma260() {
  ArmModel model;
  model.links = puma260_links();
  model.limits = puma260_limits();
  model.max_speed = puma260_max_speed();
  model.max_acceleration = puma260_max_acceleration();
  model.tool = default_tool();
  return model;
}

}  // namespace nudge::robot
