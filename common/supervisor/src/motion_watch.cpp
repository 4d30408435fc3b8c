#include "nudge/supervisor/motion_watch.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>

#include "nudge/supervisor/scene.hpp"

namespace nudge::supervisor {

MotionWatch::MotionWatch(const symmetry::Line& line, const cv::Point2d& push, int top, int bottom, cv::Size size,
                         MotionWatchParams params)
    : params_(params), size_(size) {
  tracking::validate(params_.blocks);
  const int block = params_.blocks.block_size;
  const int blocks_w = (size.width + block - 1) / block, blocks_h = (size.height + block - 1) / block;
  region_ = cv::Mat::zeros(blocks_h, blocks_w, CV_8U);
  const double side = push.x * std::cos(line.theta) + push.y * std::sin(line.theta) >= 0 ? 1.0 : -1.0;
  for (int by = 0; by < blocks_h; ++by) {
    const double y = by * block + block / 2.0;
    if (y < top || y > bottom) continue;
    for (int bx = 0; bx < blocks_w; ++bx) {
      const double beyond = side * signed_distance(line, cv::Point2d(bx * block + block / 2.0, y), size);
      if (beyond >= params_.margin_px && beyond <= params_.margin_px + params_.band_px) region_.at<uint8_t>(by, bx) = 255;
    }
  }
  region_ones_ = region_ / 255;
}

void MotionWatch::feed(const cv::Mat& frame) {
  if (frame.size() != size_)
    throw std::invalid_argument("motion watch: frame of " + std::to_string(frame.cols) + "x" + std::to_string(frame.rows) +
                                ", expected " + std::to_string(size_.width) + "x" + std::to_string(size_.height));
  cv::Mat grey;
  if (frame.channels() == 1) grey = frame.clone();
  else cv::cvtColor(frame, grey, frame.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  ++frames_;
  if (!previous_.empty()) {
    const tracking::BlockMotion motion = tracking::detect_block_motion(previous_, grey, params_.blocks);
    cv::bitwise_and(motion.moving, region_ones_, in_band_);
    const int count = cv::countNonZero(in_band_);
    max_blocks_ = std::max(max_blocks_, count);
    if (count >= params_.min_blocks) ++frames_with_motion_;
  }
  previous_ = grey;
}

}  // namespace nudge::supervisor
