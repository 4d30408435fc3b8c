#include "nudge/supervisor/scene.hpp"

#include <cmath>
#include <stdexcept>

#include "nudge/geometry/workspace.hpp"
#include "nudge/symmetry/line.hpp"

namespace nudge::supervisor {

SceneGeometry::SceneGeometry(geometry::StereoRig rig, geometry::Plane table, std::optional<Eigen::Vector3d> arm_base,
                             geometry::RigidTransform arm_to_right)
    : rig_(std::move(rig)), table_(table), table_frame_(table, arm_base), arm_to_right_(arm_to_right) {}

SceneGeometry SceneGeometry::load(const std::string& path) {
  geometry::StereoRig rig = geometry::load_rig(path);
  const geometry::Workspace workspace = geometry::load_workspace(path);
  if (!workspace.table) throw std::runtime_error(path + ": field 'table_plane' is required by the supervisor");
  if (!workspace.arm_to_right)
    throw std::runtime_error(path + ": fields 'arm_to_right_rotation' / 'arm_to_right_translation' (the camera-arm "
                             "calibration) are required by the supervisor");
  return SceneGeometry(std::move(rig), *workspace.table, workspace.arm_base, *workspace.arm_to_right);
}

Eigen::Vector3d SceneGeometry::table_to_world(const Eigen::Vector3d& table_point) const {
  return right_to_world(table_frame_.to_camera(table_point));
}

Eigen::Vector3d SceneGeometry::world_to_table(const Eigen::Vector3d& world_point) const {
  return table_frame_.to_table(world_to_right(world_point));
}

Eigen::Vector3d SceneGeometry::world_to_right(const Eigen::Vector3d& world_point) const {
  return arm_to_right_.apply(world_point);
}

Eigen::Vector3d SceneGeometry::right_to_world(const Eigen::Vector3d& right_point) const {
  return arm_to_right_.inverse().apply(right_point);
}

Eigen::Vector3d SceneGeometry::right_camera_in_world() const { return arm_to_right_.inverse().t; }

namespace {

// A camera-frame point's pixel at image size `size` (the camera's intrinsics scaled to it: the
// 1280x960 stills are the same camera at twice the resolution; pixel centres scale about the
// image's corner, x' + 0.5 = s (x + 0.5)). Nothing for a point behind the camera.
std::optional<cv::Point2d> project(const geometry::Camera& camera, const Eigen::Vector3d& p, cv::Size size) {
  if (!(p.z() > 1e-6)) return std::nullopt;
  const Eigen::Vector2d pixel = camera.project(p);
  const double sx = static_cast<double>(size.width) / camera.width;
  const double sy = static_cast<double>(size.height) / camera.height;
  return cv::Point2d(sx * (pixel.x() + 0.5) - 0.5, sy * (pixel.y() + 0.5) - 0.5);
}

std::optional<symmetry::Line> axis_line(const std::optional<cv::Point2d>& a, const std::optional<cv::Point2d>& b,
                                        cv::Size size) {
  if (!a || !b || cv::norm(*a - *b) < 1e-6) return std::nullopt;
  symmetry::Line line = line_through(*a, *b, size);
  line.seg1 = *a;
  line.seg2 = *b;
  return line;
}

Eigen::Vector3d on_table(const Eigen::Vector3d& foot, double height) { return {foot.x(), foot.y(), height}; }

}  // namespace

std::optional<cv::Point2d> SceneGeometry::project_right(const Eigen::Vector3d& world_point, cv::Size size) const {
  return project(rig_.right, world_to_right(world_point), size);
}

std::optional<cv::Point2d> SceneGeometry::project_left(const Eigen::Vector3d& world_point, cv::Size size) const {
  return project(rig_.left, rig_.R.transpose() * (world_to_right(world_point) - rig_.T), size);
}

std::optional<symmetry::Line> SceneGeometry::left_axis_line(const Eigen::Vector3d& foot, double height, cv::Size size) const {
  return axis_line(project_left(on_table(foot, 0), size), project_left(on_table(foot, height), size), size);
}

Eigen::Vector2d to_calibration(const geometry::Camera& camera, const cv::Point2d& pixel, cv::Size size) {
  const double sx = static_cast<double>(camera.width) / size.width;
  const double sy = static_cast<double>(camera.height) / size.height;
  return {sx * (pixel.x + 0.5) - 0.5, sy * (pixel.y + 0.5) - 0.5};
}

bool lines_agree(const symmetry::Line& detected, const symmetry::Line& predicted, double max_angle, double max_offset) {
  // wrapped: (R, theta) is (-R, theta -+ pi)
  const symmetry::LineDifference d = symmetry::line_difference(detected, predicted);
  return std::abs(d.theta) <= max_angle && std::abs(d.r) <= max_offset;
}

std::optional<symmetry::Line> SceneGeometry::right_axis_line(const Eigen::Vector3d& foot, double height,
                                                             cv::Size size) const {
  return axis_line(project_right(on_table(foot, 0), size), project_right(on_table(foot, height), size), size);
}

symmetry::Line line_through(const cv::Point2d& a, const cv::Point2d& b, cv::Size size) {
  const cv::Point2d d = b - a;
  double nx = -d.y, ny = d.x;
  const double length = std::hypot(nx, ny);
  nx /= length;
  ny /= length;
  double theta = std::atan2(ny, nx);
  if (theta > M_PI / 2) theta -= M_PI;
  if (theta <= -M_PI / 2) theta += M_PI;
  const cv::Point2d centre((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  symmetry::Line line;
  line.theta = theta;
  line.r = (a.x - centre.x) * std::cos(theta) + (a.y - centre.y) * std::sin(theta);
  symmetry::border_endpoints(line.r, line.theta, size.width, size.height, &line.end1, &line.end2);
  return line;
}

double signed_distance(const symmetry::Line& line, const cv::Point2d& pixel, cv::Size size) {
  const cv::Point2d centre((size.width - 1) / 2.0, (size.height - 1) / 2.0);
  return (pixel.x - centre.x) * std::cos(line.theta) + (pixel.y - centre.y) * std::sin(line.theta) - line.r;
}

}  // namespace nudge::supervisor
