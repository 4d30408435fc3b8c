#pragma once
// pose_t for the arm service's states. Where the arm stands in the world (table) frame is
// robot::BaseFrame (nudge/robot/workspace.hpp); everything on the bus is in the WORLD frame of
// docs/sim.md.
#include <Eigen/Geometry>

#include "nudge/pose_t.hpp"

namespace nudge::arm {

pose_t to_message(const Eigen::Isometry3d& pose);

}  // namespace nudge::arm
