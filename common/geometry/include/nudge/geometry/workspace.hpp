#pragma once
// What a rig file may say about the scene beyond the cameras: the table plane (thesis sec. 4.3.5:
// least-squares plane through triangulated checkerboard corners) and the arm base (the centre of
// the ch. 6 workspace ring). Both optional, both in the right camera's frame, metres:
//   table_plane: [ nx, ny, nz, d ]     # n . p + d = 0
//   arm_base: [ x, y, z ]
//   arm_to_right_rotation: [ 9 numbers, row-major ]   arm_to_right_translation: [ x, y, z ]
//     (the camera-arm calibration, App. B: p_right = R p_arm + t; the arm/world frame of docs/sim.md)
// They live in the same OpenCV YAML file as the rig, so one file describes the whole set-up.
#include <Eigen/Core>

#include <optional>
#include <string>
#include <vector>

#include "nudge/geometry/absolute_orientation.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/stereo_rig.hpp"

namespace nudge::geometry {

struct Workspace {
  std::optional<Plane> table;
  std::optional<Eigen::Vector3d> arm_base;
  std::optional<RigidTransform> arm_to_right;  // arm (world) frame -> right camera frame
};

// A plane from n . p + d = 0: normal normalised and oriented so the camera (origin) lies on the
// positive side. Throws std::invalid_argument for a zero or non-finite normal or a plane through
// the camera.
Plane plane_from_coefficients(const Eigen::Vector4d& coefficients);

// The optional fields of a rig file. Absent fields stay empty; present but malformed ones throw
// std::runtime_error naming the file and the field. Throws if the file cannot be read.
Workspace load_workspace(const std::string& path);

// save_rig plus the workspace fields that are set; written atomically.
void save_rig(const StereoRig& rig, const Workspace& workspace, const std::string& path);

// One point seen in both images (pixels, distorted): the midpoint of the shortest segment between
// the two viewing rays, right camera frame. Fails if a pixel cannot be undistorted or the rays are
// (nearly) parallel or meet behind a camera.
Outcome<Eigen::Vector3d> triangulate_point(const StereoRig& rig, const Eigen::Vector2d& left_pixel,
                                           const Eigen::Vector2d& right_pixel);

// The table plane through the triangulated corners of a board lying on the table (thesis
// sec. 4.3.5), right camera frame; `left` and `right` list the same corners in the same order.
Outcome<Plane> table_from_corners(const StereoRig& rig, const std::vector<Eigen::Vector2d>& left,
                                  const std::vector<Eigen::Vector2d>& right);

}  // namespace nudge::geometry
