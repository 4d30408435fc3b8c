#include "nudge/bus/sim_convert.hpp"

#include <stdexcept>

#include "nudge/bus/pose_convert.hpp"

namespace nudge::bus {

sim::PoseSnapshot poses_of(const sim_state_t& state) {
  if (state.num_objects != static_cast<int32_t>(state.objects.size()))
    throw std::invalid_argument("num_objects disagrees with the objects sent");
  sim::PoseSnapshot poses;
  for (const object_state_t& o : state.objects) poses.objects.push_back({o.name, position_of(o.pose), orientation_of(o.pose)});
  poses.pusher_position = position_of(state.pusher);
  poses.pusher_yaw = sim::yaw_of(orientation_of(state.pusher));
  // The tool the world service uses: the gripper at its opening, or the pad (-1).
  if (state.gripper >= 0) poses.gripper_opening = state.gripper;
  // The arm's joints as simulated (used only when the scene has an arm).
  poses.arm_joints.emplace();
  for (int j = 0; j < 6; ++j) (*poses.arm_joints)[j] = state.joints[j];
  return poses;
}

}  // namespace nudge::bus
