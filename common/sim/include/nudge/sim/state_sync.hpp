#pragma once
// Glue between a simulated state that travels between processes (the world service publishes
// it, the camera's sim backend renders it) and a World: poses only, no LCM.
//
// The world service owns the physics; a renderer keeps its own World built from the same scene
// and, for every published state, teleports the objects and the pusher to the published poses
// before rendering. Objects are matched by name, so both sides must load the same scene.
#include "nudge/sim/world.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace nudge::sim {

struct ObjectPose {
  std::string name;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // base centre, world frame
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();
};

// The poses a renderer needs: every object, and the pusher pad (centre, yaw about world z).
struct PoseSnapshot {
  std::vector<ObjectPose> objects;
  Eigen::Vector3d pusher_position = Eigen::Vector3d::Zero();
  double pusher_yaw = 0;
  // The tool at the pusher's pose: the gripper with its fingers at this opening (m), or the pad
  // when empty (the world service switches tools: --tool auto).
  std::optional<double> gripper_opening;
  std::optional<std::array<double, 6>> arm_joints;  // the PUMA 260's joints, rad (worlds with an arm)
};

// The pad's yaw for a tool orientation: the horizontal direction of the tool's x axis (the arm's
// contract: the pad faces along the tool x axis, projected onto the table). Empty when that axis
// is within about 0.06 degrees of vertical, where its horizontal direction is meaningless.
std::optional<double> pad_yaw_from_tool(const Eigen::Quaterniond& tool_orientation);

// The rotation about world z by `yaw`, and back (the yaw of a rotation's x axis).
Eigen::Quaterniond yaw_rotation(double yaw);
double yaw_of(const Eigen::Quaterniond& rotation);

// Every object's pose and the pusher's as they are in `world` (pusher yaw as given: World does
// not report it).
PoseSnapshot snapshot_poses(const World& world, double pusher_yaw);

// The poses a fraction t (0..1) of the way from `from` to `to`: positions linearly, orientations
// by spherical interpolation, the pusher's yaw the short way round. For motion blur: the camera
// renders several instants of one exposure. Objects are matched by position in the list and must
// carry the same names; otherwise `to` is returned unchanged.
PoseSnapshot interpolate_poses(const PoseSnapshot& from, const PoseSnapshot& to, double t);

// Teleports every object of `world` (matched by name), the pusher (the pad, or the gripper with
// its fingers at gripper_opening when that is set) and, when both have one, the
// arm (joints clamped to their limits) to `poses` and updates the
// derived positions, so that the next render shows them. Throws std::invalid_argument naming the
// object when a name is unknown, a pose is not finite, or the object counts differ.
void apply_poses(World& world, const PoseSnapshot& poses);

}  // namespace nudge::sim
