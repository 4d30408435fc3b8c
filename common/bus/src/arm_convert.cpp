#include "nudge/bus/arm_convert.hpp"

#include <cmath>
#include <stdexcept>

#include "nudge/bus/pose_convert.hpp"

namespace nudge::bus {

arm_state_t to_message(const ArmState& s) {
  arm_state_t m{};
  m.utime = s.utime;
  for (int j = 0; j < robot::kNumJoints; ++j) m.joints[j] = s.joints[j];
  m.gripper = s.gripper_opening;
  m.gripper_measured = s.gripper_measured;
  m.end_effector = to_message(s.tool_in_world);
  m.motion = s.motion;
  m.command_seq = s.command_seq;
  m.last_error = s.last_error;
  return m;
}

ArmState from_message(const arm_state_t& m) {
  ArmState s;
  if (!from_message(m.end_effector, &s.tool_in_world))
    throw std::invalid_argument("end_effector: position must be finite and orientation a unit quaternion");
  if (!std::isfinite(m.gripper)) throw std::invalid_argument("gripper: not finite");
  if (!std::isfinite(m.gripper_measured)) throw std::invalid_argument("gripper_measured: not finite");
  for (int j = 0; j < robot::kNumJoints; ++j) s.joints[j] = m.joints[j];
  if (!s.joints.allFinite()) throw std::invalid_argument("joints: not finite");
  s.utime = m.utime;
  s.gripper_opening = m.gripper;
  s.gripper_measured = m.gripper_measured < 0 ? -1.0 : m.gripper_measured;
  s.motion = m.motion;
  s.command_seq = m.command_seq;
  s.last_error = m.last_error;
  return s;
}

}  // namespace nudge::bus
