#include "nudge/geometry/table_texture.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>
#include <string>

namespace nudge::geometry {

namespace {

constexpr float kUndefined = -1.0f;

// The table plane in `to`'s camera frame (the rig's planes are in the right camera's frame).
Plane plane_in_camera(const StereoRig& rig, Side to, const Plane& table) {
  if (to == Side::Right) return table;
  // n . (R p + T) + d = 0 for a left-camera point p.
  Plane left = table;
  left.normal = rig.R.transpose() * table.normal;
  left.offset = table.normal.dot(rig.T) + table.offset;
  return left;
}

Eigen::Vector3d to_other_camera(const StereoRig& rig, Side to, const Eigen::Vector3d& p) {
  return to == Side::Right ? Eigen::Vector3d(rig.R.transpose() * (p - rig.T)) : rig.left_to_right(p);
}

cv::Mat grey_of(const cv::Mat& image, const char* name) {
  if (image.empty()) throw std::invalid_argument(std::string("table texture: the ") + name + " image is empty");
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument(std::string("table texture: the ") + name + " image must be 8-bit grey or BGR");
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

}  // namespace

PlaneWarp plane_warp(const StereoRig& rig, Side to, const Plane& table) {
  if (!(table.normal.norm() > 0)) throw std::invalid_argument("plane warp: the table plane's normal is zero");
  const Camera& camera = to == Side::Right ? rig.right : rig.left;
  const Camera& other = to == Side::Right ? rig.left : rig.right;
  const Plane plane = plane_in_camera(rig, to, table);
  PlaneWarp warp;
  warp.to = to;
  warp.other_size = cv::Size(other.width, other.height);
  warp.map_x.create(camera.height, camera.width, CV_32FC1);
  warp.map_y.create(camera.height, camera.width, CV_32FC1);
  for (int v = 0; v < camera.height; ++v) {
    float* mx = warp.map_x.ptr<float>(v);
    float* my = warp.map_y.ptr<float>(v);
    for (int u = 0; u < camera.width; ++u) {
      mx[u] = my[u] = kUndefined;
      const auto normalised = camera.normalise(Eigen::Vector2d(u, v));
      if (!normalised) continue;
      const Eigen::Vector3d ray(normalised.value().x(), normalised.value().y(), 1.0);
      const auto on_table = ray_meets_plane(Eigen::Vector3d::Zero(), ray, plane);
      if (!on_table) continue;  // the ray misses the table in front of the camera
      const Eigen::Vector3d seen = to_other_camera(rig, to, *on_table);
      if (seen.z() <= 1e-3) continue;
      const Eigen::Vector2d px = other.project(seen);
      if (!px.allFinite() || px.x() < 0 || px.y() < 0 || px.x() > other.width - 1 || px.y() > other.height - 1) continue;
      mx[u] = static_cast<float>(px.x());
      my[u] = static_cast<float>(px.y());
    }
  }
  return warp;
}

void validate(const TableTextureParams& params) {
  if (params.window_radius < 1) throw std::invalid_argument("table texture: window_radius must be >= 1 px");
  if (params.search_px < 0) throw std::invalid_argument("table texture: search_px must be >= 0");
  if (!(params.max_difference > 0)) throw std::invalid_argument("table texture: max_difference must be > 0");
  if (params.margin_px < 0) throw std::invalid_argument("table texture: margin_px must be >= 0");
  if (!(params.blur_sigma >= 0)) throw std::invalid_argument("table texture: blur_sigma must be >= 0");
}

cv::Mat table_texture_mask(const cv::Mat& image, const cv::Mat& other, const PlaneWarp& warp,
                           const TableTextureParams& params) {
  validate(params);
  const cv::Mat grey = grey_of(image, "camera");
  const cv::Mat other_grey = grey_of(other, "other camera's");
  if (grey.size() != warp.size() || other_grey.size() != warp.other_size)
    throw std::invalid_argument("table texture: the images are " + std::to_string(grey.cols) + "x" +
                                std::to_string(grey.rows) + " and " + std::to_string(other_grey.cols) + "x" +
                                std::to_string(other_grey.rows) + ", the calibration's " +
                                std::to_string(warp.size().width) + "x" + std::to_string(warp.size().height) +
                                " and " + std::to_string(warp.other_size.width) + "x" +
                                std::to_string(warp.other_size.height));
  cv::Mat smooth = grey, other_smooth = other_grey;
  if (params.blur_sigma > 0) {
    cv::GaussianBlur(grey, smooth, cv::Size(), params.blur_sigma);
    cv::GaussianBlur(other_grey, other_smooth, cv::Size(), params.blur_sigma);
  }
  cv::Mat warped;
  cv::remap(other_smooth, warped, warp.map_x, warp.map_y, cv::INTER_LINEAR, cv::BORDER_CONSTANT, cv::Scalar(0));

  // The best window match over small shifts of the warped image: the whole window shifts together,
  // so a shift cannot pick a different match for every pixel.
  const int s = params.search_px;
  const int w = 2 * params.window_radius + 1;
  cv::Mat padded;
  cv::copyMakeBorder(warped, padded, s, s, s, s, cv::BORDER_REPLICATE);
  cv::Mat best(grey.size(), CV_32FC1, cv::Scalar(1e9));
  cv::Mat diff, mean;
  for (int dy = -s; dy <= s; ++dy) {
    for (int dx = -s; dx <= s; ++dx) {
      const cv::Mat shifted = padded(cv::Rect(s + dx, s + dy, grey.cols, grey.rows));
      cv::absdiff(smooth, shifted, diff);
      cv::boxFilter(diff, mean, CV_32F, cv::Size(w, w), cv::Point(-1, -1), true, cv::BORDER_REPLICATE);
      best = cv::min(best, mean);
    }
  }
  cv::Mat mask = best <= params.max_difference;

  // Where the warp is undefined, or the window (and its shifts) would reach there, nothing is known.
  cv::Mat defined = warp.map_x >= 0;
  const int margin = params.window_radius + s + params.margin_px;
  cv::erode(defined, defined, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin + 1, 2 * margin + 1)),
            cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  mask &= defined;
  return mask;
}

}  // namespace nudge::geometry
