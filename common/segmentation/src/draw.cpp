// Pictures of segmentation results (thesis fig. 4.1-4.4).
#include <opencv2/imgproc.hpp>

#include "nudge/segmentation/segment.hpp"

namespace nudge::segmentation {

namespace {
using symmetry::to_bgr;

std::vector<cv::Point> fixed_point(const std::vector<cv::Point2d>& points, int shift) {
  std::vector<cv::Point> out;
  out.reserve(points.size());
  for (const auto& p : points)
    out.emplace_back(static_cast<int>(std::lround(p.x * (1 << shift))), static_cast<int>(std::lround(p.y * (1 << shift))));
  return out;
}
}  // namespace

cv::Mat draw_contour(const cv::Mat& background, const Contour& contour, const symmetry::Line& line,
                     const cv::Scalar& colour) {
  cv::Mat out = to_bgr(background);
  cv::Point2d a, b;
  symmetry::border_endpoints(line.r, line.theta, out.cols, out.rows, &a, &b);
  cv::line(out, a, b, cv::Scalar(0, 255, 255), 1, cv::LINE_AA);
  constexpr int kShift = 4;  // sub-pixel drawing
  for (const auto* side : {&contour.left, &contour.right}) {
    const std::vector<cv::Point> points = fixed_point(*side, kShift);
    if (points.size() >= 2) cv::polylines(out, points, false, colour, 2, cv::LINE_AA, kShift);
  }
  return out;
}

cv::Mat sept_image(const SeptBuffer& sept) {
  cv::Mat grey;  // weights in (0.5, 1] -> bright; -1 (empty) -> black
  sept.weights.convertTo(grey, CV_8U, 255.0);
  return grey;
}

cv::Mat contour_mask(const Contour& contour, cv::Size size) {
  cv::Mat mask = cv::Mat::zeros(size, CV_8U);
  const std::vector<cv::Point> polygon = fixed_point(contour.polygon(), 4);
  if (polygon.size() >= 3) {
    const cv::Point* data = polygon.data();
    const int count = static_cast<int>(polygon.size());
    cv::fillPoly(mask, &data, &count, 1, cv::Scalar(255), cv::LINE_8, 4);
  }
  return mask;
}

}  // namespace nudge::segmentation
