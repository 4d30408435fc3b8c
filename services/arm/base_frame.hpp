#pragma once
// Where the arm stands in the world (table) frame.
//
// The robot library works in the arm's BASE frame (DH frame 0: origin at the shoulder, z up along
// joint 1). Everything on the bus is in the WORLD frame of docs/sim.md: origin on the arm base's
// vertical axis at table-top height, z up, metres. The base therefore sits on the world z axis,
// `height` above the table top, turned by `yaw` about z (0: base x along world x).
#include <Eigen/Geometry>

namespace nudge::arm {

struct BaseFrame {
  double height = 0.33;  // shoulder above the table top, metres (docs/robot.md, SafetyConfig)
  double yaw = 0.0;      // radians about the world z axis

  Eigen::Isometry3d world_from_base() const;
  Eigen::Isometry3d to_base(const Eigen::Isometry3d& world_pose) const;
  Eigen::Isometry3d to_world(const Eigen::Isometry3d& base_pose) const;
  Eigen::Vector3d point_to_base(const Eigen::Vector3d& world_point) const;
  Eigen::Vector3d direction_to_base(const Eigen::Vector3d& world_direction) const;
  // The table plane z = 0 of the world, in the base frame.
  double table_z() const { return -height; }
};

}  // namespace nudge::arm
