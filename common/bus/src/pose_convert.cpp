#include "nudge/bus/pose_convert.hpp"

#include <cmath>

namespace nudge::bus {

pose_t to_message(const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation) {
  pose_t m{};
  for (int i = 0; i < 3; ++i) m.position[i] = position[i];
  m.orientation[0] = orientation.w();
  m.orientation[1] = orientation.x();
  m.orientation[2] = orientation.y();
  m.orientation[3] = orientation.z();
  return m;
}

pose_t to_message(const Eigen::Isometry3d& pose) {
  return to_message(Eigen::Vector3d(pose.translation()), Eigen::Quaterniond(pose.linear()));
}

Eigen::Vector3d position_of(const pose_t& m) { return {m.position[0], m.position[1], m.position[2]}; }

Eigen::Quaterniond orientation_of(const pose_t& m) {
  return {m.orientation[0], m.orientation[1], m.orientation[2], m.orientation[3]};
}

bool from_message(const pose_t& m, Eigen::Isometry3d* pose) {
  Eigen::Quaterniond q = orientation_of(m);
  const Eigen::Vector3d p = position_of(m);
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

}  // namespace nudge::bus
