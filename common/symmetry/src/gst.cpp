#include "nudge/symmetry/gst.hpp"

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "nudge/timing.hpp"

namespace nudge::symmetry {

GstResult generalized_symmetry(const cv::Mat& image, const GstParams& params) {
  if (image.empty()) throw std::invalid_argument("GST: image is empty");
  if (!(params.sigma > 0) || !std::isfinite(params.sigma)) throw std::invalid_argument("GST: sigma must be > 0");
  Stopwatch watch;
  cv::Mat grey;
  if (image.channels() == 3) cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else grey = image;
  cv::Mat gx, gy;
  cv::Sobel(grey, gx, CV_64F, 1, 0, 3);
  cv::Sobel(grey, gy, CV_64F, 0, 1, 3);
  struct Pixel {
    double x, y, r, t;
  };
  std::vector<Pixel> pixels;
  for (int y = 0; y < grey.rows; ++y) {
    for (int x = 0; x < grey.cols; ++x) {
      const double dx = gx.at<double>(y, x), dy = gy.at<double>(y, x);
      const double mag = std::hypot(dx, dy);
      if (mag > params.min_gradient) pixels.push_back({double(x), double(y), std::log1p(mag), std::atan2(dy, dx)});
    }
  }
  GstResult result;
  result.magnitude = cv::Mat::zeros(grey.size(), CV_64F);
  const double norm = 1.0 / std::sqrt(2 * M_PI * params.sigma);
  for (size_t i = 0; i < pixels.size(); ++i) {
    const Pixel& a = pixels[i];
    for (size_t j = i + 1; j < pixels.size(); ++j) {
      const Pixel& b = pixels[j];
      const double dx = b.x - a.x, dy = b.y - a.y;
      const double dist = std::hypot(dx, dy);
      const double alpha = std::atan2(dy, dx);
      const double phase = (1 - std::cos(a.t + b.t - 2 * alpha)) * (1 - std::cos(a.t - b.t));
      const double c = norm * std::exp(-dist / (2 * params.sigma)) * phase * a.r * b.r;
      // Splat onto the pixels nearest the midpoint (it lies on a half-pixel grid).
      const double mx = 0.5 * (a.x + b.x), my = 0.5 * (a.y + b.y);
      const int x0 = static_cast<int>(std::floor(mx)), y0 = static_cast<int>(std::floor(my));
      const int x1 = static_cast<int>(std::ceil(mx)), y1 = static_cast<int>(std::ceil(my));
      const double share = c / ((x1 - x0 + 1) * (y1 - y0 + 1));
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) result.magnitude.at<double>(y, x) += share;
    }
  }
  result.pairs = static_cast<int64_t>(pixels.size()) * (static_cast<int64_t>(pixels.size()) - 1) / 2;
  result.ms = watch.elapsed_ms();
  return result;
}

}  // namespace nudge::symmetry
