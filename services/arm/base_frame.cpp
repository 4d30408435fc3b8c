#include "base_frame.hpp"

namespace nudge::arm {

Eigen::Isometry3d BaseFrame::world_from_base() const {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation() = Eigen::Vector3d(0.0, 0.0, height);
  return t;
}

Eigen::Isometry3d BaseFrame::to_base(const Eigen::Isometry3d& world_pose) const {
  return world_from_base().inverse() * world_pose;
}

Eigen::Isometry3d BaseFrame::to_world(const Eigen::Isometry3d& base_pose) const {
  return world_from_base() * base_pose;
}

Eigen::Vector3d BaseFrame::point_to_base(const Eigen::Vector3d& world_point) const {
  return world_from_base().inverse() * world_point;
}

Eigen::Vector3d BaseFrame::direction_to_base(const Eigen::Vector3d& world_direction) const {
  return world_from_base().linear().transpose() * world_direction;
}

}  // namespace nudge::arm
