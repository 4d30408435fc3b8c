#include "nudge/tracking/scoring.hpp"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace nudge::tracking {

CentreLine centre_line_of_box(const cv::Rect2d& box) {
  // A box of pixels (cv::boundingRect of a mask, what the trackers were started on) covers the
  // pixel centres x .. x + width - 1.
  return {cv::Point2d(box.x + 0.5 * (box.width - 1), box.y + 0.5 * (box.height - 1)), cv::Point2d(0, 1)};
}

CentreLine centre_line_of_rotated_box(const cv::RotatedRect& box) {
  cv::Point2f corners[4];
  box.points(corners);  // bottomLeft, topLeft, topRight, bottomRight: [0]-[1] spans the height
  const cv::Point2d along_height = cv::Point2d(corners[1] - corners[0]);
  const cv::Point2d along_width = cv::Point2d(corners[2] - corners[1]);
  const cv::Point2d direction = box.size.width > box.size.height ? along_width : along_height;
  // A degenerate box has no direction of its own: call it upright.
  return {cv::Point2d(box.center), cv::norm(direction) > 0 ? direction : cv::Point2d(0, 1)};
}

CentreLine centre_line_of_polar(double r, double theta, cv::Size image) {
  const cv::Point2d centre(0.5 * (image.width - 1), 0.5 * (image.height - 1));
  const cv::Point2d normal(std::cos(theta), std::sin(theta));
  return {centre + r * normal, cv::Point2d(-normal.y, normal.x)};
}

double centre_line_error(const CentreLine& estimate, const cv::Point2d& true_bottom, const cv::Point2d& true_top,
                         int samples) {
  const double length = cv::norm(estimate.direction);
  if (!(length > 0)) throw std::invalid_argument("centre_line_error: estimate.direction is zero");
  if (samples < 2) throw std::invalid_argument("centre_line_error: samples must be >= 2");
  const cv::Point2d normal(-estimate.direction.y / length, estimate.direction.x / length);
  double sum = 0;
  for (int i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / (samples - 1);
    const cv::Point2d p = true_bottom + t * (true_top - true_bottom);
    sum += std::abs((p - estimate.point).dot(normal));
  }
  return sum / samples;
}

double mask_iou(const cv::Mat& region, const cv::Mat& truth) {
  if (region.size() != truth.size() || region.type() != CV_8U || truth.type() != CV_8U)
    throw std::invalid_argument("mask_iou: region and truth must be CV_8U masks of one size");
  const int both = cv::countNonZero(region & truth);
  const int either = cv::countNonZero(region | truth);
  return either > 0 ? static_cast<double>(both) / either : 0.0;
}

cv::Mat polygon_mask(const std::vector<cv::Point2f>& corners, cv::Size size) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8U);
  std::vector<cv::Point> pixels;
  // Corners are pixel centres: round to the nearest pixel.
  for (const cv::Point2f& c : corners) pixels.emplace_back(cvRound(c.x), cvRound(c.y));
  if (pixels.size() >= 3) cv::fillConvexPoly(mask, pixels, cv::Scalar(255));
  return mask;
}

}  // namespace nudge::tracking
