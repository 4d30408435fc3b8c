#include "nudge/tracking/block_motion.hpp"

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace nudge::tracking {

namespace {
void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}
bool odd_positive(int n) { return n >= 1 && n % 2 == 1; }

// Lines 1-13 of Algorithm 5: sums of |I1 - I0| per block. Differences are accumulated per column
// over a block's rows first (a loop the compiler vectorises), then summed across the block.
cv::Mat block_difference_sums(const cv::Mat& previous, const cv::Mat& current, int block) {
  const int width = current.cols, height = current.rows;
  const int bw = (width + block - 1) / block, bh = (height + block - 1) / block;
  cv::Mat sums(bh, bw, CV_32F);
  std::vector<uint16_t> column_sums(width);  // <= 256 rows x 255: fits 16 bits
  for (int by = 0; by < bh; ++by) {
    std::fill(column_sums.begin(), column_sums.end(), uint16_t{0});
    const int y_end = std::min(height, (by + 1) * block);
    for (int y = by * block; y < y_end; ++y) {
      const uint8_t* a = previous.ptr<uint8_t>(y);
      const uint8_t* b = current.ptr<uint8_t>(y);
      uint16_t* acc = column_sums.data();
      for (int x = 0; x < width; ++x) acc[x] = static_cast<uint16_t>(acc[x] + (std::max(a[x], b[x]) - std::min(a[x], b[x])));
    }
    float* out = sums.ptr<float>(by);
    const int rows_in_block = y_end - by * block;
    for (int bx = 0; bx < bw; ++bx) {
      const int x_end = std::min(width, (bx + 1) * block);
      uint32_t s = 0;
      for (int x = bx * block; x < x_end; ++x) s += column_sums[x];
      // Partial blocks at the border are scaled to a full block's area.
      out[bx] = static_cast<float>(s) * (block * block) / (rows_in_block * (x_end - bx * block));
    }
  }
  return sums;
}
}  // namespace

void validate(const BlockMotionParams& p) {
  require(p.block_size >= 1 && p.block_size <= 256, "block motion parameter block_size must be in [1, 256]");
  require(p.threshold_factor > 0 && p.threshold_factor < 1e6, "block motion parameter threshold_factor must be > 0");
  require(p.min_mean_difference >= 0 && p.min_mean_difference <= 255,
          "block motion parameter min_mean_difference must be in [0, 255]");
  require(odd_positive(p.median_size) && p.median_size <= 5, "block motion parameter median_size must be 1, 3 or 5");
  require(odd_positive(p.dilate_size) && p.dilate_size <= 15, "block motion parameter dilate_size must be odd, 1..15");
}

BlockMotion detect_block_motion(const cv::Mat& previous, const cv::Mat& current, const BlockMotionParams& params) {
  validate(params);
  require(!current.empty() && current.type() == CV_8UC1 && previous.type() == CV_8UC1 &&
              previous.size() == current.size(),
          "block motion needs two 8-bit grey frames of the same size");
  BlockMotion result;
  result.block_size = params.block_size;
  result.block_sums = block_difference_sums(previous, current, params.block_size);

  // Line 14: relative threshold (plus the optional absolute noise floor).
  const double mean = cv::mean(result.block_sums)[0];
  const double floor = params.min_mean_difference * params.block_size * params.block_size;
  const double threshold = std::max(params.threshold_factor * mean, floor);
  cv::Mat moving;
  cv::threshold(result.block_sums, moving, threshold, 1.0, cv::THRESH_BINARY);
  moving.convertTo(result.moving, CV_8U);

  // Lines 15-16: the median removes isolated noisy blocks, dilation recovers the object's contour.
  cv::Mat filtered = result.moving.clone();
  if (params.median_size > 1) cv::medianBlur(result.moving, filtered, params.median_size);
  result.moving_blocks = cv::countNonZero(filtered);
  if (params.dilate_size > 1) {
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, {params.dilate_size, params.dilate_size});
    cv::dilate(filtered, result.blocks, kernel);
  } else {
    result.blocks = filtered;
  }
  return result;
}

cv::Mat upscale_blocks(const cv::Mat& blocks, int block_size, int width, int height) {
  require(blocks.type() == CV_8UC1 && block_size >= 1, "upscale_blocks needs an 8-bit block image");
  cv::Mat mask(height, width, CV_8U);
  for (int y = 0; y < height; ++y) {
    const uint8_t* src = blocks.ptr<uint8_t>(std::min(blocks.rows - 1, y / block_size));
    uint8_t* dst = mask.ptr<uint8_t>(y);
    for (int x = 0; x < width; ++x) dst[x] = src[std::min(blocks.cols - 1, x / block_size)] ? 255 : 0;
  }
  return mask;
}

cv::Mat mask_edges(const cv::Mat& edges, const cv::Mat& motion_mask) {
  require(edges.type() == CV_8UC1 && motion_mask.type() == CV_8UC1 && edges.size() == motion_mask.size(),
          "mask_edges needs 8-bit edge and mask images of the same size");
  cv::Mat out;
  cv::bitwise_and(edges, motion_mask, out);
  return out;
}

}  // namespace nudge::tracking
