#pragma once
// The one description of the arm's workspace that every service reads (docs/robot.md, "The
// workspace file"): where the arm stands on the table, its tool, the ring its tool point may reach
// and the table clearance. The arm checks motions with it, triangulation proposes candidates
// inside the same ring, and the simulated world mounts the same tool on the same arm, so a
// candidate one proposes is one the other can nudge.
//
// Frames: the WORLD (table) frame of docs/sim.md has its origin on the arm base's vertical axis
// at table-top height, z up. The arm's base frame (DH frame 0, see puma260.hpp) sits on that axis
// `shoulder_height` above the table, turned by `base_yaw` about z.
//
// The defaults below are the only ones in the code; config/workspace.yaml spells them out.
#include <Eigen/Geometry>

#include <string>

namespace nudge::robot {

struct ArmModel;
struct SafetyConfig;

struct Workspace {
  double base_yaw = 0.0;          // radians: the base x axis about the world z axis
  double shoulder_height = 0.33;  // shoulder (base frame origin) above the table top, m
  double tool_length = 0.15;      // tool point along the flange z axis, m (pad / gripper centre)
  double ring_inner = 0.150;      // the tool point's horizontal distance from the base axis, m
  double ring_outer = 0.350;      //   (Li 2008, sec. 6.3: roughly 150-350 mm)
  double table_margin = 0.005;    // tool point, wrist and elbow stay this far above the table, m
};

// Throws std::invalid_argument naming the field when a value makes no sense.
void validate(const Workspace& workspace);

// Reads a workspace file (OpenCV YAML, docs/robot.md): every field is required, unknown fields
// are refused (typos). Throws std::runtime_error naming the file and the field.
Workspace load_workspace(const std::string& path);

// Writes `workspace` as a workspace file (atomically).
void save_workspace(const Workspace& workspace, const std::string& path);

// The workspace's tool on the model (tool point `tool_length` along the flange z axis).
void apply_workspace(const Workspace& workspace, ArmModel* model);
// The workspace's table (table_z, table_margin) and ring on a safety configuration.
void apply_workspace(const Workspace& workspace, SafetyConfig* safety);

// Where the arm base stands in the world frame: on the world z axis, `height` above the table
// top, turned by `yaw` about z. Converts between the world frame (the bus) and the base frame
// (the robot library).
struct BaseFrame {
  double height = Workspace{}.shoulder_height;  // metres
  double yaw = Workspace{}.base_yaw;            // radians about the world z axis

  static BaseFrame of(const Workspace& workspace) { return {workspace.shoulder_height, workspace.base_yaw}; }

  Eigen::Isometry3d world_from_base() const;
  Eigen::Isometry3d to_base(const Eigen::Isometry3d& world_pose) const;
  Eigen::Isometry3d to_world(const Eigen::Isometry3d& base_pose) const;
  Eigen::Vector3d point_to_base(const Eigen::Vector3d& world_point) const;
  Eigen::Vector3d direction_to_base(const Eigen::Vector3d& world_direction) const;
  // The table plane z = 0 of the world, in the base frame.
  double table_z() const { return -height; }
};

}  // namespace nudge::robot
