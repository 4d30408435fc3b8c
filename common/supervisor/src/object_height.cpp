#include "nudge/supervisor/object_height.hpp"

#include <stdexcept>
#include <string>

#include "nudge/supervisor/line_search.hpp"

namespace nudge::supervisor {

void validate(const HeightParams& p) {
  auto require = [](bool ok, const std::string& what) {
    if (!ok) throw std::invalid_argument("HeightParams::" + what);
  };
  require(p.min_pair_width_px > 0 && p.max_pair_width_px > p.min_pair_width_px,
          "min_pair_width_px must be positive and below max_pair_width_px");
  require(p.window_deg > 0 && p.window_deg < 90, "window_deg must be in (0, 90)");
  require(p.window_px > 0, "window_px must be positive");
  require(p.margin_m >= 0 && p.margin_m < 1, "margin_m must be in [0, 1) m");
}

namespace {

// The right camera's ray through `pixel` (image `size`), world frame: its direction (not
// normalised); nothing when the pixel does not map to a ray.
std::optional<Eigen::Vector3d> right_ray(const SceneGeometry& scene, const cv::Point2d& pixel, cv::Size size) {
  const geometry::Camera& camera = scene.rig().right;
  const auto normalised = camera.normalise(to_calibration(camera, pixel, size));
  if (!normalised) return std::nullopt;
  return scene.right_to_world(Eigen::Vector3d(normalised->x(), normalised->y(), 1.0)) - scene.right_camera_in_world();
}

}  // namespace

std::optional<double> ray_height_over(const SceneGeometry& scene, const Eigen::Vector3d& foot, const cv::Point2d& pixel,
                                      cv::Size size) {
  const auto direction = right_ray(scene, pixel, size);
  if (!direction) return std::nullopt;
  const Eigen::Vector3d origin = scene.right_camera_in_world();
  const Eigen::Vector3d& ray = *direction;
  const Eigen::Vector2d across = ray.head<2>();
  if (across.squaredNorm() < 1e-12) return std::nullopt;  // looking straight down the vertical
  const double t = (foot - origin).head<2>().dot(across) / across.squaredNorm();
  if (!(t > 0)) return std::nullopt;  // the vertical is behind the camera
  return origin.z() + t * ray.z();
}

std::optional<Eigen::Vector3d> table_point_under_line_foot(const SceneGeometry& scene, const symmetry::Line& line,
                                                           cv::Size size) {
  if (cv::norm(line.seg1 - line.seg2) < 1) return std::nullopt;  // no support
  const cv::Point2d lower = line.seg1.y >= line.seg2.y ? line.seg1 : line.seg2;
  const auto direction = right_ray(scene, lower, size);
  if (!direction) return std::nullopt;
  const Eigen::Vector3d origin = scene.right_camera_in_world();
  const Eigen::Vector3d& ray = *direction;
  if (!(ray.z() < -1e-9)) return std::nullopt;  // level or looking up: it never meets the table
  return Eigen::Vector3d(origin - (origin.z() / ray.z()) * ray);
}

std::optional<double> depth_beyond_line_foot(const SceneGeometry& scene, const symmetry::Line& line,
                                             const Eigen::Vector3d& foot, cv::Size size) {
  const auto on_table = table_point_under_line_foot(scene, line, size);
  if (!on_table) return std::nullopt;
  const Eigen::Vector2d view = (foot - scene.right_camera_in_world()).head<2>();
  if (view.norm() < 1e-9) return std::nullopt;
  return (foot - *on_table).head<2>().dot(view.normalized());
}

namespace {

// The end of a line's support segment higher in the image.
cv::Point2d upper_end(const symmetry::Line& line) { return line.seg1.y <= line.seg2.y ? line.seg1 : line.seg2; }

}  // namespace

std::optional<double> measure_object_height(const SceneGeometry& scene, const cv::Mat& right_still,
                                            const symmetry::Line& object_line, const Eigen::Vector3d& foot,
                                            const HeightParams& params) {
  validate(params);
  if (right_still.empty()) return std::nullopt;
  LineSearchParams search;
  search.window_deg = params.window_deg;
  search.window_px = params.window_px * right_still.cols / 640.0;
  search.min_pair_width_px = params.min_pair_width_px;
  search.max_pair_width_px = params.max_pair_width_px;
  // find_line_near prefers lines standing on the prediction's seg1: the support's lower end.
  symmetry::Line prediction = object_line;
  if (prediction.seg1.y < prediction.seg2.y) std::swap(prediction.seg1, prediction.seg2);
  const std::optional<symmetry::Line> narrow = find_line_near(right_still, prediction, search);
  if (!narrow) return std::nullopt;
  const cv::Point2d a = upper_end(*narrow), b = upper_end(object_line);
  return ray_height_over(scene, foot, a.y <= b.y ? a : b, right_still.size());
}

}  // namespace nudge::supervisor
