#include "base_frame.hpp"

#include <cmath>

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

pose_t to_message(const Eigen::Isometry3d& pose) {
  pose_t m{};
  const Eigen::Quaterniond q(pose.linear());
  for (int i = 0; i < 3; ++i) m.position[i] = pose.translation()[i];
  m.orientation[0] = q.w();
  m.orientation[1] = q.x();
  m.orientation[2] = q.y();
  m.orientation[3] = q.z();
  return m;
}

bool from_message(const pose_t& m, Eigen::Isometry3d* pose) {
  Eigen::Quaterniond q(m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]);
  const Eigen::Vector3d p(m.position[0], m.position[1], m.position[2]);
  if (!p.allFinite() || !q.coeffs().allFinite() || std::fabs(q.norm() - 1.0) > 1e-3) return false;
  q.normalize();
  *pose = Eigen::Isometry3d::Identity();
  pose->linear() = q.toRotationMatrix();
  pose->translation() = p;
  return true;
}

bool is_unset(const pose_t& m) {
  for (double v : m.position)
    if (v != 0.0) return false;
  for (double v : m.orientation)
    if (v != 0.0) return false;
  return true;
}

}  // namespace nudge::arm
