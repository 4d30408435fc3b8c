#include "nudge/symmetry/photo.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "nudge/timing.hpp"

namespace nudge::symmetry {

PhotoDetection detect_photo(const cv::Mat& image, const PhotoOptions& options) {
  if (image.empty()) throw std::invalid_argument("image is empty");
  if (options.max_side < 0) throw std::invalid_argument("max_side must be >= 0");
  if (!options.canny.empty() && options.canny.size() != 2) throw std::invalid_argument("canny needs LOW and HIGH");
  PhotoDetection out;
  out.working_image = image;
  const int long_side = std::max(image.cols, image.rows);
  if (options.max_side > 0 && long_side > options.max_side) {
    // Each side at least 1 px: a strip 4000 x 2 px scaled by 1/4 would otherwise have no rows.
    const double f = static_cast<double>(options.max_side) / long_side;
    const cv::Size scaled(std::max(1, static_cast<int>(std::lround(image.cols * f))),
                         std::max(1, static_cast<int>(std::lround(image.rows * f))));
    cv::resize(image, out.working_image, scaled, 0, 0, cv::INTER_AREA);
  }
  const cv::Mat& work = out.working_image;
  const double short_side = std::min(work.cols, work.rows), work_long = std::max(work.cols, work.rows);
  out.params = options.params;
  out.params.dmin = options.dmin >= 0 ? options.dmin : std::max(5.0, 0.05 * short_side);
  out.params.dmax = options.dmax >= 0 ? options.dmax : 0.5 * work_long;
  if (options.dmin < 0 && options.dmax < 0 && out.params.dmin > out.params.dmax)
    throw std::invalid_argument("the image is " + std::to_string(image.cols) + "x" + std::to_string(image.rows) +
                                " px: too small for symmetry (edge pairs at least " +
                                std::to_string(static_cast<int>(out.params.dmin)) +
                                " px apart need a longer side of at least twice that)");
  out.edge_params.blur_sigma = options.blur >= 0 ? options.blur : std::max(1.0, short_side / 480.0);
  if (options.canny.size() == 2) {
    out.edge_params.canny_low = options.canny[0];
    out.edge_params.canny_high = options.canny[1];
  } else {
    out.edge_params.auto_canny = true;
  }
  out.edge_params.gradients = out.params.mirror_tolerance_deg > 0;
  Detector detector(out.params, out.edge_params);
  Stopwatch watch;
  out.edges = detect_edges(work, out.edge_params, &out.edge_image);
  const double edges_ms = watch.elapsed_ms();
  out.at_working_size = detector.detect(out.edges);
  out.at_working_size.ms.edges_ms = edges_ms;
  out.in_image = out.at_working_size;
  if (work.size() != image.size()) {
    out.in_image.width = image.cols;
    out.in_image.height = image.rows;
    for (auto& l : out.in_image.lines) l = map_line(l, work.size(), image.size());
  }
  return out;
}

bool competition_match(const Line& detected, const cv::Point2d& truth_a, const cv::Point2d& truth_b,
                       double max_angle_deg, double centre_fraction) {
  const cv::Point2d truth_dir = truth_b - truth_a;
  const cv::Point2d line_dir(-std::sin(detected.theta), std::cos(detected.theta));
  const double cosine = std::fabs(truth_dir.dot(line_dir)) / std::max(1e-12, cv::norm(truth_dir));
  const double angle_deg = std::acos(std::min(1.0, cosine)) * 180.0 / M_PI;
  const double detected_length = cv::norm(detected.seg2 - detected.seg1);
  const double shorter = std::min(detected_length, cv::norm(truth_dir));
  const double centre_distance = cv::norm(0.5 * (detected.seg1 + detected.seg2) - 0.5 * (truth_a + truth_b));
  return angle_deg < max_angle_deg && centre_distance < centre_fraction * shorter;
}

}  // namespace nudge::symmetry
