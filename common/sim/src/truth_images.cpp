#include "nudge/sim/truth_images.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace nudge::sim {

namespace {
constexpr double kHalfRange = 0.5;     // m
constexpr double kSteps = 65534.0;     // codes 1..65535
}  // namespace

cv::Mat encode_surface(const cv::Mat& points) {
  if (points.type() != CV_32FC3) throw std::invalid_argument("encode_surface: expected CV_32FC3 points");
  cv::Mat out(points.size(), CV_16UC3, cv::Scalar(0, 0, 0));
  for (int y = 0; y < points.rows; ++y) {
    const cv::Vec3f* in = points.ptr<cv::Vec3f>(y);
    cv::Vec3w* dst = out.ptr<cv::Vec3w>(y);
    for (int x = 0; x < points.cols; ++x) {
      if (std::isnan(in[x][0])) continue;
      for (int k = 0; k < 3; ++k) {
        const double c = std::clamp(static_cast<double>(in[x][k]), -kHalfRange, kHalfRange);
        dst[x][k] = static_cast<unsigned short>(std::lround((c + kHalfRange) / (2 * kHalfRange) * kSteps) + 1);
      }
    }
  }
  return out;
}

cv::Mat decode_surface(const cv::Mat& encoded) {
  if (encoded.type() != CV_16UC3)
    throw std::invalid_argument("decode_surface: expected a 16-bit 3-channel image (CV_16UC3)");
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cv::Mat out(encoded.size(), CV_32FC3, cv::Scalar(nan, nan, nan));
  for (int y = 0; y < encoded.rows; ++y) {
    const cv::Vec3w* in = encoded.ptr<cv::Vec3w>(y);
    cv::Vec3f* dst = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < encoded.cols; ++x) {
      if (in[x][0] == 0) continue;
      for (int k = 0; k < 3; ++k)
        dst[x][k] = static_cast<float>((in[x][k] - 1) / kSteps * (2 * kHalfRange) - kHalfRange);
    }
  }
  return out;
}

}  // namespace nudge::sim
