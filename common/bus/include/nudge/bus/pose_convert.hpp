#pragma once
// pose_t <-> Eigen. pose_t is a position in metres and a unit quaternion (w, x, y, z).
#include <Eigen/Geometry>

#include "nudge/pose_t.hpp"

namespace nudge::bus {

pose_t to_message(const Eigen::Isometry3d& pose);
pose_t to_message(const Eigen::Vector3d& position, const Eigen::Quaterniond& orientation);

// The numbers as sent, unchecked (the simulator's own poses, which it trusts).
Eigen::Vector3d position_of(const pose_t& message);
Eigen::Quaterniond orientation_of(const pose_t& message);

// The pose a pose_t describes. False when a number is not finite or the quaternion is not of
// unit length (within 1e-3; it is then normalised exactly).
bool from_message(const pose_t& message, Eigen::Isometry3d* pose);

// Whether every number of the pose_t is zero (a sender that left the field unset).
bool is_unset(const pose_t& message);

}  // namespace nudge::bus
