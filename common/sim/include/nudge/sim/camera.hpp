#pragma once
// Cameras of the simulated stereo rig and ground-truth projection of symmetry axes.
//
// Camera frame: OpenCV's (x right, y down, z forward). Pose is world -> camera:
// X_cam = R * X_world + t. The intrinsics and lens are a geometry::Camera (one lens model shared
// with the stereo geometry): K = [f 0 cx; 0 f cy; 0 0 1] with pixel indices from 0 at pixel
// centres, so the principal point is the image centre ((w-1)/2, (h-1)/2), and optional lens
// distortion in OpenCV's model (k1, k2, p1, p2, k3), zero by default.
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/sim/scene.hpp"

#include <Eigen/Core>

#include <array>
#include <string>

namespace nudge::sim {

struct CameraModel {
  std::string name;  // "left" / "right"
  double fovy = 0;   // radians
  geometry::Camera lens{0, 0};  // image size, K and distortion; projection is delegated to it
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();  // world -> camera rotation
  Eigen::Vector3d t = Eigen::Vector3d::Zero();      // world -> camera translation

  bool distorted() const;
  Eigen::Vector3d centre() const { return -R.transpose() * t; }  // in the world frame
  Eigen::Vector3d forward() const { return R.row(2).transpose(); }  // optical axis, world frame
  Eigen::Vector3d to_camera(const Eigen::Vector3d& world) const { return R * world + t; }
  // Pixel coordinates of a world point, distortion included; z (depth) <= 0: behind the camera.
  Eigen::Vector2d project(const Eigen::Vector3d& world, double* depth = nullptr) const;
  // Normalised image coordinates (x/z, y/z) -> distorted normalised coordinates.
  Eigen::Vector2d distort(const Eigen::Vector2d& normalised) const;
  // Pixel -> undistorted normalised coordinates (geometry::Camera::normalise). Throws
  // std::domain_error naming the camera and the pixel where the lens model cannot be inverted.
  Eigen::Vector2d undistort(const Eigen::Vector2d& pixel) const;
};

// Size of the ideal pinhole image (same f, principal point at its centre) that covers every pixel
// of `camera`'s distorted image, with a small margin; the camera's own size without distortion.
// Rendering draws this image and warps it.
struct PinholeCanvas {
  int width = 0, height = 0;
};
PinholeCanvas pinhole_canvas(const CameraModel& camera);

// The calibrated rig of two sim cameras (e.g. World::snapshot_camera's, which a StereoRig does not
// hold): their lenses, and R, T with X_right = R * X_left + T.
geometry::StereoRig calibrated(const CameraModel& left, const CameraModel& right);

// The two cameras of a verged stereo rig, index 0 = left, 1 = right.
struct StereoRig {
  std::array<CameraModel, 2> cameras;
  // Pose of the right camera relative to the left: X_right = R * X_left + t.
  Eigen::Matrix3d R_right_left() const;
  Eigen::Vector3d t_right_left() const;
  // The rig as the stereo geometry sees it: both lenses and the left -> right extrinsics.
  geometry::StereoRig calibrated() const { return sim::calibrated(cameras[0], cameras[1]); }
};

StereoRig make_rig(const RigSpec& spec);

// The same camera rendering `scale` times as many pixels across (same pose and field of view).
CameraModel scaled(const CameraModel& camera, int scale);

// A 3D symmetry axis: a point on it (the object's base centre on the table), its unit direction
// and the object's height along it.
struct Axis3d {
  Eigen::Vector3d base = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();
  double height = 0;
  Eigen::Vector3d top() const { return base + height * direction; }
};

// A symmetry line in the image in the project's convention (docs/architecture.md, "Conventions"):
// (cos theta, sin theta) is the line's normal about the image centre ((w-1)/2, (h-1)/2); theta = 0
// is a vertical line; theta in (-pi/2, pi/2]. `bottom`/`top` are the projections of the axis' ends.
struct ImageLine {
  bool valid = false;  // false when the axis projects to a point or lies behind the camera
  double r = 0;
  double theta = 0;
  Eigen::Vector2d bottom = Eigen::Vector2d::Zero();
  Eigen::Vector2d top = Eigen::Vector2d::Zero();
};

// (R, theta) of the image line through two pixel positions; valid = false if they coincide.
ImageLine line_through(const Eigen::Vector2d& a, const Eigen::Vector2d& b, int width, int height);
ImageLine project_axis(const CameraModel& camera, const Axis3d& axis);

// Signed distance (px) from a pixel to an image line, positive on the normal's side.
double signed_distance(const ImageLine& line, const Eigen::Vector2d& pixel, int width, int height);

}  // namespace nudge::sim
