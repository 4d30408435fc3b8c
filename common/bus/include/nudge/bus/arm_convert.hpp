#pragma once
// arm_state_t <-> the robot library's types.
#include <Eigen/Geometry>

#include <cstdint>
#include <string>

#include "nudge/arm_state_t.hpp"
#include "nudge/robot/types.hpp"

namespace nudge::bus {

// What the arm service reports, in library types.
struct ArmState {
  int64_t utime = 0;
  robot::JointVector joints = robot::JointVector::Zero();  // radians
  double gripper_opening = 0;                               // metres, as commanded
  double gripper_measured = -1;                             // metres, as measured; -1: no sensor
  Eigen::Isometry3d tool_in_world = Eigen::Isometry3d::Identity();  // the tool point, WORLD frame
  int8_t motion = arm_state_t::MOTION_IDLE;                 // arm_state_t::MOTION_*
  int64_t command_seq = -1;                                 // last command accepted
  std::string last_error;                                   // "" if none
};

arm_state_t to_message(const ArmState& state);

// Throws std::invalid_argument naming the field: joints or gripper not finite, end_effector not
// a finite position with a unit quaternion.
ArmState from_message(const arm_state_t& message);

}  // namespace nudge::bus
