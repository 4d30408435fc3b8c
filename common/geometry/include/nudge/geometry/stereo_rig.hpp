#pragma once
// Calibrated stereo rig (thesis sec. 4.3.2): per-camera intrinsics and lens distortion in OpenCV's
// model, and the extrinsics mapping left-camera coordinates into the right camera's frame
// (eq. 4.5: x_right = R x_left + T). Lengths in metres.
#include <Eigen/Core>

#include <array>
#include <string>

#include "nudge/geometry/outcome.hpp"

namespace nudge::geometry {

struct Camera {
  int width = 640, height = 480;                     // image size, px
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();   // [fx s cx; 0 fy cy; 0 0 1]
  std::array<double, 5> distortion{};                // k1, k2, p1, p2, k3 (OpenCV / Bouguet order)

  // Pixel (u, v) -> undistorted normalised image coordinates (x, y) with z = 1, by the fixed-point
  // iteration of Bouguet's comp_distortion_oulu.m. Fails (with a reason) where it does not converge.
  Outcome<Eigen::Vector2d> normalise(const Eigen::Vector2d& pixel) const;
  // The forward model: camera-frame point -> distorted pixel (as cv::projectPoints). z must be > 0.
  Eigen::Vector2d project(const Eigen::Vector3d& point) const;
  // Normalised (x, y) -> distorted normalised coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& normalised) const;
};

struct StereoRig {
  Camera left, right;
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // left -> right rotation
  Eigen::Vector3d T = Eigen::Vector3d::Zero();      // left -> right translation, m
  // The left camera's centre in the right camera's frame (the right camera's centre is the origin).
  Eigen::Vector3d left_centre() const { return T; }
  Eigen::Vector3d left_to_right(const Eigen::Vector3d& p) const { return R * p + T; }
};

// Throws std::invalid_argument naming the offending field (non-positive focal length, image size,
// non-finite numbers, R not a rotation).
void validate(const StereoRig& rig);

// OpenCV FileStorage YAML:
//   left: { image_width, image_height, camera_matrix (3x3), distortion_coefficients (4 or 5) }
//   right: { ... }   R (3x3)   T (3x1)
// load_rig throws std::runtime_error naming the file and the missing or malformed field.
StereoRig load_rig(const std::string& path);
// Written atomically (temporary file + rename): a crash leaves the previous file intact.
void save_rig(const StereoRig& rig, const std::string& path);

}  // namespace nudge::geometry
