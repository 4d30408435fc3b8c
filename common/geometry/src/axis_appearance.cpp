#include "nudge/geometry/axis_appearance.hpp"

#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>

namespace nudge::geometry {

namespace {

// Mean BGR of the window about the pixel nearest `p`; nothing when the window leaves the image.
std::optional<cv::Vec3d> mean_colour(const cv::Mat& image, const Eigen::Vector2d& p, int w) {
  const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
  if (!std::isfinite(p.x()) || !std::isfinite(p.y()) || x - w < 0 || y - w < 0 || x + w >= image.cols ||
      y + w >= image.rows)
    return std::nullopt;
  cv::Vec3d sum(0, 0, 0);
  for (int dy = -w; dy <= w; ++dy) {
    for (int dx = -w; dx <= w; ++dx) {
      if (image.channels() == 3) {
        const cv::Vec3b c = image.at<cv::Vec3b>(y + dy, x + dx);
        sum += cv::Vec3d(c[0], c[1], c[2]);
      } else {
        const double g = image.at<uint8_t>(y + dy, x + dx);
        sum += cv::Vec3d(g, g, g);
      }
    }
  }
  return sum / static_cast<double>((2 * w + 1) * (2 * w + 1));
}

void check_image(const cv::Mat& image, const Camera& camera, const char* side) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 3 && image.channels() != 1))
    throw std::invalid_argument(std::string("axis appearance: the ") + side + " image must be 8-bit BGR or grey");
  if (image.cols != camera.width || image.rows != camera.height)
    throw std::invalid_argument(std::string("axis appearance: the ") + side + " image is " +
                                std::to_string(image.cols) + "x" + std::to_string(image.rows) + ", the rig's " +
                                std::to_string(camera.width) + "x" + std::to_string(camera.height));
}

}  // namespace

void validate(const AxisAppearanceParams& p) {
  if (!(p.lowest_m >= 0)) throw std::invalid_argument("axis appearance parameter lowest_m must be >= 0");
  if (!(p.step_m > 0)) throw std::invalid_argument("axis appearance parameter step_m must be > 0");
  if (p.window_px < 0 || p.window_px > 10) throw std::invalid_argument("axis appearance parameter window_px must be in [0, 10]");
  if (!(p.colour_tolerance >= 0 && p.colour_tolerance <= 765))
    throw std::invalid_argument("axis appearance parameter colour_tolerance must be in [0, 765]");
  if (p.min_samples < 1) throw std::invalid_argument("axis appearance parameter min_samples must be >= 1");
}

Outcome<double> axis_colour_agreement(const StereoRig& rig, const cv::Mat& left_image, const cv::Mat& right_image,
                                      const Segment3& axis, const Eigen::Vector3d& table_hit, const Plane& table,
                                      double top_m, const AxisAppearanceParams& params) {
  validate(params);
  check_image(left_image, rig.left, "left");
  check_image(right_image, rig.right, "right");
  Eigen::Vector3d up = axis.direction();
  if (!up.allFinite()) return Outcome<double>::failure("the axis has no direction");
  if (up.dot(table.normal) < 0) up = -up;
  // Heights are measured along the axis from where it meets the table.
  const double along_per_height = 1.0 / std::max(1e-6, up.dot(table.normal));
  int samples = 0, agree = 0;
  for (double h = params.lowest_m; h <= top_m + 1e-9; h += params.step_m) {
    const Eigen::Vector3d point = table_hit + h * along_per_height * up;
    const Eigen::Vector3d in_left = rig.R.transpose() * (point - rig.T);
    if (!(point.z() > 0) || !(in_left.z() > 0)) continue;
    const auto l = mean_colour(left_image, rig.left.project(in_left), params.window_px);
    const auto r = mean_colour(right_image, rig.right.project(point), params.window_px);
    if (!l || !r) continue;
    ++samples;
    const cv::Vec3d d = *l - *r;
    agree += std::fabs(d[0]) + std::fabs(d[1]) + std::fabs(d[2]) <= params.colour_tolerance;
  }
  if (samples < params.min_samples)
    return Outcome<double>::failure("only " + std::to_string(samples) + " heights of the axis are in both images");
  return Outcome<double>::success(static_cast<double>(agree) / samples);
}

}  // namespace nudge::geometry
