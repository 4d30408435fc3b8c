#include "nudge/supervisor/grasp.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>
#include <vector>

#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/workspace.hpp"

namespace nudge::supervisor {

namespace {

// The largest 8-connected blob of a mask, labelled within the bounding box of the mask's pixels
// only (a full-size still's mask is mostly empty: labelling all of it cost the grasp plan ~4 ms).
class LargestBlob {
 public:
  explicit LargestBlob(const cv::Mat& mask) {
    box_ = cv::boundingRect(mask);  // of the non-zero pixels: no list of them (35 000 in a still's mask)
    if (box_.empty()) return;
    cv::Mat stats, centroids;
    const int count = cv::connectedComponentsWithStats(mask(box_) != 0, labels_, stats, centroids, 8, CV_32S);
    int best_area = 0;
    for (int label = 1; label < count; ++label) {
      const int area = stats.at<int>(label, cv::CC_STAT_AREA);
      if (area > best_area) label_ = label, best_area = area;
    }
  }
  bool empty() const { return label_ == 0; }
  bool contains(int x, int y) const {
    return box_.contains(cv::Point(x, y)) && labels_.at<int>(y - box_.y, x - box_.x) == label_;
  }
  // The blob's first and last column in row `y` (image coordinates); nothing when it has none.
  std::optional<std::pair<int, int>> extent_in_row(int y) const {
    if (y < box_.y || y >= box_.y + box_.height) return std::nullopt;
    const int* row = labels_.ptr<int>(y - box_.y);
    int first = -1, last = -1;
    for (int x = 0; x < box_.width; ++x)
      if (row[x] == label_) {
        if (first < 0) first = x;
        last = x;
      }
    if (first < 0) return std::nullopt;
    return std::make_pair(box_.x + first, box_.x + last);
  }
  // The blob's width in row `y`: from its first to its last pixel there (0 when it has none).
  int width_in_row(int y) const {
    const auto extent = extent_in_row(y);
    return extent ? extent->second - extent->first + 1 : 0;
  }
  // The width in row `y` of an object symmetric about column `x`: the blob's, or twice its
  // narrower side of x when one side is longer by more than 15 % of the width (what sticks out
  // on one side only: a mug's handle). A line a few pixels off the middle keeps the full width.
  // 0 when x is outside the blob's row.
  int symmetric_width_in_row(int y, double x) const {
    const auto extent = extent_in_row(y);
    if (!extent) return 0;
    const double left = x - extent->first + 0.5, right = extent->second - x + 0.5;
    if (left <= 0 || right <= 0) return 0;
    if (std::abs(left - right) <= 0.15 * (left + right)) return extent->second - extent->first + 1;
    return static_cast<int>(std::lround(2 * std::min(left, right)));
  }

 private:
  cv::Rect box_;
  cv::Mat labels_;
  int label_ = 0;
};

// The right camera's focal length in pixels of an image of `size` (a still is the same camera at
// another resolution).
double right_focal_px(const SceneGeometry& scene, cv::Size size) {
  const geometry::Camera& camera = scene.rig().right;
  return camera.K(0, 0) * static_cast<double>(size.width) / camera.width;
}

}  // namespace

std::optional<MaskOnLine> read_mask_on_line(const cv::Mat& mask, const symmetry::Line& line) {
  if (mask.empty() || mask.type() != CV_8U) return std::nullopt;
  // Points of the line: (x - cx) cos(theta) + (y - cy) sin(theta) = R.
  const double c = std::cos(line.theta), s = std::sin(line.theta);
  if (std::abs(c) < 0.2) return std::nullopt;
  const LargestBlob blob(mask);
  if (blob.empty()) return std::nullopt;
  const double cx = (mask.cols - 1) / 2.0, cy = (mask.rows - 1) / 2.0;
  std::optional<cv::Point2d> top, front;
  for (int y = 0; y < mask.rows; ++y) {
    const double x = cx + (line.r - (y - cy) * s) / c;
    const int column = static_cast<int>(std::lround(x));
    if (column < 0 || column >= mask.cols || !blob.contains(column, y)) continue;
    if (!top) top = cv::Point2d(x, y);
    front = cv::Point2d(x, y);
  }
  if (!top) return std::nullopt;
  MaskOnLine reading{*top, *front, 0, 0, mask.size()};
  const int band = std::max(2, static_cast<int>((front->y - top->y) / 5));
  for (int y = static_cast<int>(top->y); y <= static_cast<int>(front->y); ++y) {
    const int width = blob.symmetric_width_in_row(y, cx + (line.r - (y - cy) * s) / c);
    reading.widest_px = std::max(reading.widest_px, width);
    if (y >= front->y - band) reading.base_width_px = std::max(reading.base_width_px, width);
  }
  return reading;
}

std::optional<cv::Point2d> object_top(const cv::Mat& mask, const symmetry::Line& line) {
  const auto reading = read_mask_on_line(mask, line);
  if (!reading) return std::nullopt;
  return reading->top;
}

std::optional<Eigen::Vector3d> foot_from_mask(const SceneGeometry& scene, const MaskOnLine& right_mask) {
  if (right_mask.base_width_px < kMinBaseShareOfWidest * right_mask.widest_px) return std::nullopt;
  const geometry::Camera& camera = scene.rig().right;
  const auto normalised = camera.normalise(to_calibration(camera, right_mask.front, right_mask.size));
  if (!normalised) return std::nullopt;
  const auto base_front = geometry::ray_meets_plane(Eigen::Vector3d::Zero(), Eigen::Vector3d(normalised->x(), normalised->y(), 1.0),
                                                    scene.table());  // right camera frame
  if (!base_front) return std::nullopt;
  // At the foot's depth a pixel spans depth / f metres (f at the mask's size).
  const double focal = right_focal_px(scene, right_mask.size);
  const double radius = 0.5 * right_mask.base_width_px * base_front->z() / focal;
  const Eigen::Vector3d front = scene.right_to_world(*base_front);
  Eigen::Vector3d along = front - scene.right_camera_in_world();
  along.z() = 0;
  if (along.norm() < 1e-9) return std::nullopt;
  const Eigen::Vector3d foot = front + radius * along.normalized();
  return Eigen::Vector3d(foot.x(), foot.y(), 0.0);
}

std::optional<Eigen::Vector3d> foot_from_mask(const SceneGeometry& scene, const cv::Mat& mask, const symmetry::Line& line) {
  const auto reading = read_mask_on_line(mask, line);
  if (!reading) return std::nullopt;
  return foot_from_mask(scene, *reading);
}

bool mask_front_hidden_by(const SceneGeometry& scene, const MaskOnLine& right_mask, const Eigen::Vector3d& stands_at,
                          const Eigen::Vector3d& place, double radius, double height) {
  const Eigen::Vector3d camera = scene.right_camera_in_world();
  if ((place - camera).head<2>().norm() >= (stands_at - camera).head<2>().norm()) return false;  // behind it
  const Eigen::Vector3d base(place.x(), place.y(), 0.0), top(place.x(), place.y(), height);
  Eigen::Vector3d away = base - camera;
  away.z() = 0;
  if (away.norm() < 1e-9) return false;
  away = radius * away.normalized();
  const auto base_px = scene.project_right(base, right_mask.size), top_px = scene.project_right(top, right_mask.size);
  // Seen from above, its outline reaches up to its top's far rim and down to its base's near rim.
  const auto far_rim = scene.project_right(top + away, right_mask.size), near_rim = scene.project_right(base - away, right_mask.size);
  const double depth = scene.world_to_right(base).z();
  if (!base_px || !top_px || !far_rim || !near_rim || !(depth > 0)) return false;
  const double radius_px = radius * right_focal_px(scene, right_mask.size) / depth;
  // The pixel just below the front: the first one the mask does not hold on the line.
  const cv::Point2d below = right_mask.front + cv::Point2d(0, std::max(2.0, 0.1 * radius_px));
  if (below.y < far_rim->y || below.y > near_rim->y) return false;
  const double t = std::abs(base_px->y - top_px->y) > 1e-9 ? (below.y - base_px->y) / (top_px->y - base_px->y) : 0.0;
  const double axis_x = base_px->x + t * (top_px->x - base_px->x);
  return std::abs(below.x - axis_x) <= radius_px;
}

std::optional<double> object_width_at(const SceneGeometry& scene, const cv::Mat& right_mask, const Eigen::Vector3d& foot,
                                      double height) {
  if (right_mask.empty() || right_mask.type() != CV_8U) return std::nullopt;
  const Eigen::Vector3d point(foot.x(), foot.y(), height);
  const auto pixel = scene.project_right(point, right_mask.size());
  if (!pixel) return std::nullopt;
  const int row = static_cast<int>(std::lround(pixel->y));
  if (row < 0 || row >= right_mask.rows) return std::nullopt;
  const LargestBlob blob(right_mask);
  const int width_px = blob.width_in_row(row);
  if (width_px <= 0) return std::nullopt;
  const double focal = right_focal_px(scene, right_mask.size());
  const double depth = scene.world_to_right(point).z();
  if (!(depth > 0)) return std::nullopt;
  return width_px * depth / focal;
}

double grip_height(double top_height, const GraspTargetParams& params) {
  return std::max(top_height - params.grip_depth_m, params.min_grip_fraction * top_height);
}

GraspTarget grasp_target(const SceneGeometry& scene, const cv::Point2d& left_top, const cv::Point2d& right_top,
                         cv::Size still_size, const Eigen::Vector3d& foot, const GraspTargetParams& params) {
  GraspTarget target;
  target.foot = Eigen::Vector3d(foot.x(), foot.y(), 0.0);
  const geometry::StereoRig& rig = scene.rig();
  const auto top = geometry::triangulate_point(rig, to_calibration(rig.left, left_top, still_size),
                                               to_calibration(rig.right, right_top, still_size));
  if (!top) {
    target.reason = "the object's top does not triangulate: " + top.reason();
    return target;
  }
  target.top = scene.right_to_world(*top);
  const double height = target.top.z();
  char text[128];
  if (!(height <= params.max_object_height_m)) {
    std::snprintf(text, sizeof text, "the object's top triangulates %.0f mm above the table: no object is that tall", height * 1e3);
    target.reason = text;
    return target;
  }
  // Theta: the right camera's angle of view over the table at the object (fig. 7.4).
  const Eigen::Vector3d camera = scene.right_camera_in_world();
  const double theta = std::atan2(camera.z() - height, (camera - target.top).head<2>().norm());
  target.overestimate_m = params.top_radius_m * std::tan(std::max(0.0, theta));
  target.top_height_m = height - target.overestimate_m;
  target.grasp_height_m = grip_height(target.top_height_m, params);
  if (target.grasp_height_m < params.min_grasp_height_m) {
    std::snprintf(text, sizeof text, "the object's top (%.0f mm, %.0f mm lowered) is too low to grasp", height * 1e3,
                  target.overestimate_m * 1e3);
    target.reason = text;
  }
  return target;
}

cv::Rect cylinder_box(const SceneGeometry& scene, const Eigen::Vector3d& centre, double radius, double bottom,
                      double top, cv::Size size) {
  double x0 = 1e9, y0 = 1e9, x1 = -1e9, y1 = -1e9;
  for (double z : {bottom, top})
    for (int k = 0; k < 16; ++k) {  // the rims, every 22.5 deg: their image hull bounds the cylinder
      const double a = k * M_PI / 8;
      const auto pixel = scene.project_right({centre.x() + radius * std::cos(a), centre.y() + radius * std::sin(a), z}, size);
      if (!pixel) return {};
      x0 = std::min(x0, pixel->x), y0 = std::min(y0, pixel->y);
      x1 = std::max(x1, pixel->x), y1 = std::max(y1, pixel->y);
    }
  const cv::Rect box(cv::Point(static_cast<int>(std::floor(x0)), static_cast<int>(std::floor(y0))),
                     cv::Point(static_cast<int>(std::ceil(x1)) + 1, static_cast<int>(std::ceil(y1)) + 1));
  return box & cv::Rect(cv::Point(0, 0), size);
}

}  // namespace nudge::supervisor
