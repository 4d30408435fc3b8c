#include "nudge/sim/camera.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nudge::sim {

using Eigen::Matrix3d;
using Eigen::Vector2d;
using Eigen::Vector3d;

bool CameraModel::distorted() const {
  for (double d : lens.distortion)
    if (d != 0) return true;
  return false;
}

Vector2d CameraModel::distort(const Vector2d& n) const { return lens.distort(n); }

Vector2d CameraModel::undistort(const Vector2d& pixel) const {
  const geometry::Outcome<Vector2d> n = lens.normalise(pixel);
  if (!n) throw std::domain_error("camera '" + name + "': " + n.reason());
  return *n;
}

Vector2d CameraModel::project(const Vector3d& world, double* depth) const {
  const Vector3d c = to_camera(world);
  if (depth) *depth = c.z();
  return lens.project(c);
}

PinholeCanvas pinhole_canvas(const CameraModel& camera) {
  PinholeCanvas canvas{camera.lens.width, camera.lens.height};
  if (!camera.distorted()) return canvas;
  // The undistorted positions of the border pixels bound the pinhole image needed.
  double ex = 0, ey = 0;
  auto visit = [&](double u, double v) {
    const Vector2d n = camera.undistort(Vector2d(u, v));
    ex = std::max(ex, std::fabs(camera.lens.K(0, 0) * n.x()));
    ey = std::max(ey, std::fabs(camera.lens.K(1, 1) * n.y()));
  };
  for (int u = 0; u < camera.lens.width; ++u) {
    visit(u, 0);
    visit(u, camera.lens.height - 1);
  }
  for (int v = 0; v < camera.lens.height; ++v) {
    visit(0, v);
    visit(camera.lens.width - 1, v);
  }
  // Even sizes keep the centre at (size - 1) / 2; 2 px margin for interpolation.
  canvas.width = std::max(camera.lens.width, 2 * static_cast<int>(std::ceil(ex + 2)));
  canvas.height = std::max(camera.lens.height, 2 * static_cast<int>(std::ceil(ey + 2)));
  return canvas;
}

Matrix3d StereoRig::R_right_left() const {
  return calibrated().R;
}

Vector3d StereoRig::t_right_left() const {
  return calibrated().T;
}

geometry::StereoRig calibrated(const CameraModel& left, const CameraModel& right) {
  geometry::StereoRig rig;
  rig.left = left.lens;
  rig.right = right.lens;
  // X_right = R_r (R_l^T (X_left - t_l)) + t_r.
  rig.R = right.R * left.R.transpose();
  rig.T = right.t - rig.R * left.t;
  return rig;
}

StereoRig make_rig(const RigSpec& spec) {
  if (!(spec.distance > 0) || !(spec.baseline > 0) || spec.width <= 0 || spec.height <= 0 ||
      !(spec.fovy > 0 && spec.fovy < M_PI))
    throw std::invalid_argument("make_rig: distance, baseline, size and fovy must be positive");
  const double ce = std::cos(spec.elevation), se = std::sin(spec.elevation);
  const Vector3d from_target(ce * std::cos(spec.azimuth), ce * std::sin(spec.azimuth), se);
  const Vector3d centre = spec.target + spec.distance * from_target;
  const Vector3d forward = -from_target;
  const Vector3d right = forward.cross(Vector3d::UnitZ()).normalized();
  const Vector3d down = forward.cross(right);

  const double f = 0.5 * spec.height / std::tan(0.5 * spec.fovy);
  Matrix3d K = Matrix3d::Identity();
  K(0, 0) = f;
  K(1, 1) = f;
  K(0, 2) = 0.5 * (spec.width - 1);
  K(1, 2) = 0.5 * (spec.height - 1);

  StereoRig rig;
  const double half = 0.5 * spec.vergence;
  for (int i = 0; i < 2; ++i) {
    const double side = i == 0 ? -1.0 : 1.0;  // left camera on -right
    // Each camera turns inwards by half the vergence, about the rig's vertical (down) axis.
    const Vector3d fwd = std::cos(half) * forward - side * std::sin(half) * right;
    const Vector3d rgt = std::cos(half) * right + side * std::sin(half) * forward;
    CameraModel& cam = rig.cameras[i];
    cam.name = i == 0 ? "left" : "right";
    cam.fovy = spec.fovy;
    cam.lens.width = spec.width;
    cam.lens.height = spec.height;
    cam.lens.K = K;
    cam.lens.distortion = spec.distortion;
    cam.R.row(0) = rgt.transpose();
    cam.R.row(1) = down.transpose();
    cam.R.row(2) = fwd.transpose();
    const Vector3d position = centre + side * 0.5 * spec.baseline * right;
    cam.t = -cam.R * position;
  }
  return rig;
}

CameraModel scaled(const CameraModel& camera, int scale) {
  if (scale < 1) throw std::invalid_argument("scaled: scale must be >= 1");
  CameraModel out = camera;
  geometry::Camera& lens = out.lens;
  lens.width = camera.lens.width * scale;
  lens.height = camera.lens.height * scale;
  lens.K(0, 0) = camera.lens.K(0, 0) * scale;
  lens.K(1, 1) = camera.lens.K(1, 1) * scale;
  lens.K(0, 2) = 0.5 * (lens.width - 1);
  lens.K(1, 2) = 0.5 * (lens.height - 1);
  return out;
}

ImageLine line_through(const Vector2d& a, const Vector2d& b, int width, int height) {
  ImageLine line;
  line.bottom = a;
  line.top = b;
  const Vector2d d = b - a;
  if (!(d.norm() > 1e-9)) return line;
  // A normal of direction d is (d.y, -d.x) / |d| (or its opposite): theta = atan2(-d.x, d.y),
  // then folded into (-pi/2, pi/2] (R changes sign with the normal).
  double theta = std::atan2(-d.x(), d.y());
  if (theta <= -M_PI / 2) theta += M_PI;
  if (theta > M_PI / 2) theta -= M_PI;
  const Vector2d n(std::cos(theta), std::sin(theta));
  const Vector2d c(0.5 * (width - 1), 0.5 * (height - 1));
  line.theta = theta;
  line.r = n.dot(a - c);
  line.valid = true;
  return line;
}

ImageLine project_axis(const CameraModel& camera, const Axis3d& axis) {
  double z0 = 0, z1 = 0;
  const Vector2d a = camera.project(axis.base, &z0);
  const Vector2d b = camera.project(axis.top(), &z1);
  if (!(z0 > 0 && z1 > 0)) {
    ImageLine line;
    line.bottom = a;
    line.top = b;
    return line;
  }
  return line_through(a, b, camera.lens.width, camera.lens.height);
}

double signed_distance(const ImageLine& line, const Vector2d& pixel, int width, int height) {
  const Vector2d c(0.5 * (width - 1), 0.5 * (height - 1));
  return std::cos(line.theta) * (pixel.x() - c.x()) + std::sin(line.theta) * (pixel.y() - c.y()) -
         line.r;
}

}  // namespace nudge::sim
