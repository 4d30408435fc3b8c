#include "nudge/sim/state_sync.hpp"

#include <cmath>
#include <stdexcept>

namespace nudge::sim {

std::optional<double> pad_yaw_from_tool(const Eigen::Quaterniond& tool_orientation) {
  if (!tool_orientation.coeffs().allFinite() || tool_orientation.norm() < 1e-9) return std::nullopt;
  const Eigen::Vector3d x = tool_orientation.normalized() * Eigen::Vector3d::UnitX();
  if (std::hypot(x.x(), x.y()) < 1e-3) return std::nullopt;
  return std::atan2(x.y(), x.x());
}

Eigen::Quaterniond yaw_rotation(double yaw) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()));
}

double yaw_of(const Eigen::Quaterniond& rotation) {
  const Eigen::Vector3d x = rotation.normalized() * Eigen::Vector3d::UnitX();
  return std::atan2(x.y(), x.x());
}

PoseSnapshot snapshot_poses(const World& world, double pusher_yaw) {
  PoseSnapshot out;
  for (int i = 0; i < world.num_objects(); ++i) {
    const ObjectState st = world.object(i);
    out.objects.push_back({st.name, st.position, st.orientation});
  }
  out.pusher_position = world.pusher_position();
  out.pusher_yaw = pusher_yaw;
  if (world.gripper_in_use()) out.gripper_opening = world.gripper_opening();
  if (world.has_arm()) out.arm_joints = world.arm_joints();
  return out;
}

void apply_poses(World& world, const PoseSnapshot& poses) {
  if (static_cast<int>(poses.objects.size()) != world.num_objects())
    throw std::invalid_argument("the state has " + std::to_string(poses.objects.size()) + " objects, the scene " +
                                std::to_string(world.num_objects()) + " (is it the same scene?)");
  for (const ObjectPose& o : poses.objects) {
    if (!o.position.allFinite() || !o.orientation.coeffs().allFinite() || o.orientation.norm() < 1e-9)
      throw std::invalid_argument("object '" + o.name + "': pose is not finite");
  }
  if (!poses.pusher_position.allFinite() || !std::isfinite(poses.pusher_yaw))
    throw std::invalid_argument("pusher: pose is not finite");
  if (poses.gripper_opening && !std::isfinite(*poses.gripper_opening))
    throw std::invalid_argument("gripper: opening is not finite");
  if (poses.arm_joints)
    for (double j : *poses.arm_joints)
      if (!std::isfinite(j)) throw std::invalid_argument("arm: joints are not finite");
  // Checked before anything moves, so a bad state leaves the world as it was.
  std::vector<int> index;
  for (const ObjectPose& o : poses.objects) {
    index.push_back(world.object_index(o.name));
    if (index.back() < 0) throw std::invalid_argument("object '" + o.name + "' is not in the scene");
  }
  // The pusher first: set_object_pose() recomputes the derived positions of every body (the
  // mocap pusher included); with no objects, set_state() of the current state does it.
  if (poses.arm_joints && world.has_arm()) world.set_arm_joints(*poses.arm_joints);
  if (poses.gripper_opening)
    world.place_gripper(poses.pusher_position, poses.pusher_yaw, *poses.gripper_opening);
  else
    world.set_pusher(poses.pusher_position, poses.pusher_yaw);
  for (size_t k = 0; k < index.size(); ++k)
    world.set_object_pose(index[k], poses.objects[k].position, poses.objects[k].orientation);
  if (index.empty()) world.set_state(world.state());
}

PoseSnapshot interpolate_poses(const PoseSnapshot& from, const PoseSnapshot& to, double t) {
  if (from.objects.size() != to.objects.size()) return to;
  PoseSnapshot out = to;
  for (size_t i = 0; i < to.objects.size(); ++i) {
    if (from.objects[i].name != to.objects[i].name) return to;
    out.objects[i].position = (1 - t) * from.objects[i].position + t * to.objects[i].position;
    out.objects[i].orientation = from.objects[i].orientation.slerp(t, to.objects[i].orientation);
  }
  out.pusher_position = (1 - t) * from.pusher_position + t * to.pusher_position;
  const double turn = std::remainder(to.pusher_yaw - from.pusher_yaw, 2 * M_PI);
  out.pusher_yaw = from.pusher_yaw + t * turn;
  if (from.gripper_opening && to.gripper_opening)
    out.gripper_opening = (1 - t) * *from.gripper_opening + t * *to.gripper_opening;
  if (from.arm_joints && to.arm_joints)
    for (int j = 0; j < 6; ++j) (*out.arm_joints)[j] = (1 - t) * (*from.arm_joints)[j] + t * (*to.arm_joints)[j];
  return out;
}

}  // namespace nudge::sim
