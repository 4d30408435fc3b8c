#pragma once
// The PUMA 260 arm model (Li 2008, appendix B.3.1, Table B.1) and its configurable parts.
//
// Frames: the base frame is DH frame 0 of Table B.1: origin at the shoulder (where the joint 1
// and joint 2 axes meet), z up along the joint 1 axis. The flange frame is DH frame 6: its origin
// is the wrist centre (d5 = d6 = 0) and its z axis the last joint's axis, pointing out of the
// wrist. The tool point is a fixed transform from the flange (gripper fingertips, or the contact
// point of the L-shaped nudging sponge).
#include <Eigen/Geometry>

#include <array>

#include "nudge/robot/types.hpp"

namespace nudge::robot {

// One link in standard Denavit-Hartenberg notation (Paul & Zhang 1986 numbering):
// T_i = Rot_z(theta_i) Trans_z(d_i) Trans_x(a_i) Rot_x(alpha_i).
struct DhLink {
  double alpha = 0;  // radians
  double a = 0;      // metres
  double d = 0;      // metres
};

struct JointLimits {
  JointVector lower = JointVector::Zero();  // radians
  JointVector upper = JointVector::Zero();  // radians
};

struct ArmModel {
  std::array<DhLink, kNumJoints> links{};
  JointLimits limits;
  JointVector max_speed = JointVector::Ones();         // rad/s, per joint
  JointVector max_acceleration = JointVector::Ones();  // rad/s^2, per joint
  Eigen::Isometry3d tool = Eigen::Isometry3d::Identity();  // tool point in the flange frame
};

// Table B.1: alpha = [90, 0, -90, 90, -90, 0] deg, a = [0, 0.2032, 0, 0, 0, 0] m,
// d = [0, 0, 0.12624, 0.2032, 0, 0] m.
std::array<DhLink, kNumJoints> puma260_links();

// Joint limits, degrees: J1 -160..160, J2 -45..225, J3 -225..45, J4 -110..170, J5 -100..100,
// J6 -266..266: the PUMA 560 ranges of Corke's Robotics Toolbox (mdl_puma560.m), same DH
// convention. See docs/robot.md for why J2/J3 read this way round.
JointLimits puma260_limits();

// Conservative speed and acceleration limits for joint-space moves (not from the thesis: the
// PUMA's own maxima are far higher; these keep nudges gentle). See docs/robot.md.
JointVector puma260_max_speed();
JointVector puma260_max_acceleration();

// The default tool: a point Workspace::tool_length (0.15 m) along the flange z axis (gripper
// fingertips / sponge), with the flange's orientation. Measure and configure it for a real
// effector (the workspace file, workspace.hpp).
Eigen::Isometry3d default_tool();

// Table B.1 links, the limits above, conservative speeds and the default tool.
ArmModel puma260();

}  // namespace nudge::robot
