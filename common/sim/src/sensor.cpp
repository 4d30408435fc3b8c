#include "nudge/sim/sensor.hpp"

#include <opencv2/imgproc.hpp>

#include <stdexcept>
#include <string>

namespace nudge::sim {

void add_sensor_noise(cv::Mat& image, double sigma, std::mt19937_64& rng) {
  if (sigma <= 0 || image.empty()) return;
  if (image.depth() != CV_8U && image.depth() != CV_32F)
    throw std::invalid_argument("add_sensor_noise: image depth must be 8-bit or float, not OpenCV depth " +
                                std::to_string(image.depth()));
  // Draw in float and add in float: an 8-bit image rounds once, after the noise is in.
  cv::Mat noise(image.size(), CV_32FC(image.channels()));
  std::normal_distribution<float> normal(0.0f, static_cast<float>(sigma));
  const int values_per_row = noise.cols * noise.channels();
  for (int y = 0; y < noise.rows; ++y) {
    float* row = noise.ptr<float>(y);
    for (int x = 0; x < values_per_row; ++x) row[x] = normal(rng);
  }
  if (image.depth() == CV_32F) {
    image += noise;
    return;
  }
  cv::Mat sum;
  image.convertTo(sum, noise.type());
  sum += noise;
  sum.convertTo(image, image.type());  // saturating
}

cv::Mat average_frames(const std::vector<cv::Mat>& frames) {
  if (frames.empty()) throw std::invalid_argument("average_frames: no frames");
  const cv::Mat& first = frames.front();
  if (first.empty()) throw std::invalid_argument("average_frames: frame 0 is empty");
  cv::Mat sum = cv::Mat::zeros(first.size(), CV_32FC(first.channels()));
  for (size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].size() != first.size() || frames[i].type() != first.type())
      throw std::invalid_argument("average_frames: frame " + std::to_string(i) +
                                  " differs in size or type from frame 0");
    cv::accumulate(frames[i], sum);
  }
  sum /= static_cast<double>(frames.size());
  return sum;
}

}  // namespace nudge::sim
