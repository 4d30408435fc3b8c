#pragma once
// The calibrated set-up the supervisor reasons in: the stereo rig, the table, and the arm (world)
// frame of docs/sim.md. The triangulation service reports positions in its table frame
// (geometry::TableFrame); the arm takes the world frame; the camera sees pixels. This class is the
// one place that converts between the three.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <string>

#include "nudge/geometry/absolute_orientation.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/symmetry/detector.hpp"

namespace nudge::supervisor {

class SceneGeometry {
 public:
  // `arm_base` is the TableFrame origin hint the triangulation service used (the rig file's field).
  SceneGeometry(geometry::StereoRig rig, geometry::Plane table, std::optional<Eigen::Vector3d> arm_base,
                geometry::RigidTransform arm_to_right);
  // A calibration file (rig + table_plane + arm_base + arm_to_right_*: nudge-exp-calibration-sim's
  // output). Throws std::runtime_error naming the file and the missing field.
  static SceneGeometry load(const std::string& path);

  // CANDIDATES / AXES positions (the triangulation service's table frame) -> world frame.
  Eigen::Vector3d table_to_world(const Eigen::Vector3d& table_point) const;
  Eigen::Vector3d world_to_table(const Eigen::Vector3d& world_point) const;
  Eigen::Vector3d world_to_right(const Eigen::Vector3d& world_point) const;
  Eigen::Vector3d right_to_world(const Eigen::Vector3d& right_point) const;
  Eigen::Vector3d right_camera_in_world() const;

  // Pixel of a world point in the right camera at image size `size` (the calibration's intrinsics
  // scaled to it: the 1280x960 stills are the same camera at twice the resolution). Nothing for a
  // point behind the camera.
  std::optional<cv::Point2d> project_right(const Eigen::Vector3d& world_point, cv::Size size) const;
  // The image line of a vertical axis standing on the table at `foot` (world, z ignored) and `height`
  // tall, in the right camera at `size`; (R, theta) in the project's convention with border ends.
  std::optional<symmetry::Line> right_axis_line(const Eigen::Vector3d& foot, double height, cv::Size size) const;

  // The same for the left camera (the rig's extrinsics: x_right = R x_left + T).
  std::optional<cv::Point2d> project_left(const Eigen::Vector3d& world_point, cv::Size size) const;
  std::optional<symmetry::Line> left_axis_line(const Eigen::Vector3d& foot, double height, cv::Size size) const;

  const geometry::StereoRig& rig() const { return rig_; }
  const geometry::Plane& table() const { return table_; }

 private:
  geometry::StereoRig rig_;
  geometry::Plane table_;
  geometry::TableFrame table_frame_;
  geometry::RigidTransform arm_to_right_;
};

// A pixel of an image of `size` at the calibration's resolution (the inverse of the scaling of
// project_right and project_left): the stills are the same camera at another resolution.
Eigen::Vector2d to_calibration(const geometry::Camera& camera, const cv::Point2d& pixel, cv::Size size);

// Whether a detected line is the predicted one: angles within `max_angle` (radians) and R within
// `max_offset` px, comparing (R, theta) in the form nearer the prediction.
bool lines_agree(const symmetry::Line& detected, const symmetry::Line& predicted, double max_angle, double max_offset);

// The line through two image points in the project's (R, theta) convention for an image of `size`:
// normal (cos theta, sin theta), theta in (-pi/2, pi/2], R from the image centre ((w-1)/2, (h-1)/2).
symmetry::Line line_through(const cv::Point2d& a, const cv::Point2d& b, cv::Size size);
// Signed distance of a pixel from a line (positive on the side its normal points to).
double signed_distance(const symmetry::Line& line, const cv::Point2d& pixel, cv::Size size);

}  // namespace nudge::supervisor
