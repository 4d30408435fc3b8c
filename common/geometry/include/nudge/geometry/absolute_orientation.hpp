#pragma once
// Absolute orientation (Arun, Huang & Blostein 1987): the rigid motion that best maps one set of
// 3D points onto corresponding points in another frame, in the least-squares sense. Thesis App. B:
// camera-arm calibration: the arm marks points known in its own frame, the stereo pair
// triangulates the same points (checkerboard corners) in the camera frame, and this gives the
// transform between the two frames.
#include <Eigen/Core>
#include <Eigen/Geometry>

#include <vector>

#include "nudge/geometry/outcome.hpp"

namespace nudge::geometry {

// to = R * from + t.
struct RigidTransform {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Vector3d apply(const Eigen::Vector3d& p) const { return R * p + t; }
  RigidTransform inverse() const { return {R.transpose(), -R.transpose() * t}; }
};

struct AbsoluteOrientation {
  RigidTransform transform;
  double rms_residual = 0;  // of |R from_i + t - to_i|, in the points' unit
  double max_residual = 0;
};

// R minimises sum |R (from_i - mean_from) - (to_i - mean_to)|^2: the SVD of the cross-covariance
// H = sum (from_i - mean_from)(to_i - mean_to)^T = U S V^T gives R = V U^T. Arun's method can return
// a reflection (det = -1) when the points are coplanar, as a board's corners on a table are, or
// noisy: the sign of the smallest singular direction is then flipped (Umeyama 1991), which keeps
// R a rotation and is the least-squares rotation in every case. Fails for fewer than 3 pairs,
// sizes that differ, non-finite points, or points (nearly) on one line, where the rotation about
// that line is undetermined.
Outcome<AbsoluteOrientation> absolute_orientation(const std::vector<Eigen::Vector3d>& from,
                                                  const std::vector<Eigen::Vector3d>& to);

// Angle of the rotation between two rotation matrices (of R_a R_b^T), radians in [0, pi].
double rotation_angle_between(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b);

}  // namespace nudge::geometry
