#include "pose_message.hpp"

namespace nudge::arm {

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

}  // namespace nudge::arm
