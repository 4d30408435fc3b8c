#include "nudge/tracking/refine.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace nudge::tracking {

namespace {
void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}

// The line's frame: pivot (nearest point to the image centre) and unit normal / direction.
struct LineFrame {
  cv::Point2d pivot, normal, dir;
  LineFrame(double r, double theta, int width, int height)
      : normal(std::cos(theta), std::sin(theta)), dir(-std::sin(theta), std::cos(theta)) {
    pivot = cv::Point2d(0.5 * (width - 1), 0.5 * (height - 1)) + r * normal;
  }
  double across(const cv::Point2d& p) const { return (p - pivot).dot(normal); }
  double along(const cv::Point2d& p) const { return (p - pivot).dot(dir); }
  cv::Point2d mirror(const cv::Point2d& p) const { return p - 2.0 * across(p) * normal; }
  cv::Point2d at(double across_px, double along_px) const { return pivot + across_px * normal + along_px * dir; }
};

bool any_in_window(const cv::Mat& blocks, int cx, int cy, int half) {
  for (int y = std::max(0, cy - half); y <= std::min(blocks.rows - 1, cy + half); ++y) {
    const uint8_t* row = blocks.ptr<uint8_t>(y);
    for (int x = std::max(0, cx - half); x <= std::min(blocks.cols - 1, cx + half); ++x)
      if (row[x]) return true;
  }
  return false;
}

int count_in_window(const cv::Mat& blocks, int cx, int cy, int half) {
  int n = 0;
  for (int y = std::max(0, cy - half); y <= std::min(blocks.rows - 1, cy + half); ++y) {
    const uint8_t* row = blocks.ptr<uint8_t>(y);
    for (int x = std::max(0, cx - half); x <= std::min(blocks.cols - 1, cx + half); ++x) n += row[x] ? 1 : 0;
  }
  return n;
}

cv::Point2d block_centre(int bx, int by, int block_size) {
  return {bx * block_size + 0.5 * (block_size - 1), by * block_size + 0.5 * (block_size - 1)};
}
}  // namespace

void validate(const RefineParams& p) {
  require(p.mirror_window >= 0 && p.mirror_window <= 8, "refine parameter mirror_window must be in [0, 8]");
  require(p.fill_window >= 1 && p.fill_window <= 8, "refine parameter fill_window must be in [1, 8]");
  const int neighbours = (2 * p.fill_window + 1) * (2 * p.fill_window + 1) - 1;
  require(p.fill_min_neighbours >= 1 && p.fill_min_neighbours <= neighbours + 1,
          "refine parameter fill_min_neighbours must be in [1, window size]");
}

cv::Mat refine_blocks(const cv::Mat& blocks, int block_size, int width, int height, double r, double theta,
                      const RefineParams& params) {
  validate(params);
  require(blocks.type() == CV_8UC1 && block_size >= 1, "refine_blocks needs an 8-bit block image");
  const LineFrame line(r, theta, width, height);
  cv::Mat symmetric = cv::Mat::zeros(blocks.size(), CV_8U);
  for (int by = 0; by < blocks.rows; ++by) {
    for (int bx = 0; bx < blocks.cols; ++bx) {
      if (!blocks.at<uint8_t>(by, bx)) continue;
      const cv::Point2d m = line.mirror(block_centre(bx, by, block_size));
      const int mx = static_cast<int>(std::floor(m.x / block_size)), my = static_cast<int>(std::floor(m.y / block_size));
      if (any_in_window(blocks, mx, my, params.mirror_window)) symmetric.at<uint8_t>(by, bx) = 1;
    }
  }
  cv::Mat filled = symmetric.clone();
  for (int by = 0; by < blocks.rows; ++by) {
    for (int bx = 0; bx < blocks.cols; ++bx) {
      if (symmetric.at<uint8_t>(by, bx)) continue;
      if (count_in_window(symmetric, bx, by, params.fill_window) >= params.fill_min_neighbours)
        filled.at<uint8_t>(by, bx) = 1;
    }
  }
  return filled;
}

RotatedBox rotated_box(const cv::Mat& blocks, int block_size, int width, int height, double r, double theta) {
  require(blocks.type() == CV_8UC1 && block_size >= 1, "rotated_box needs an 8-bit block image");
  const LineFrame line(r, theta, width, height);
  RotatedBox box;
  for (int by = 0; by < blocks.rows; ++by) {
    for (int bx = 0; bx < blocks.cols; ++bx) {
      if (!blocks.at<uint8_t>(by, bx)) continue;
      // The block's four pixel corners, clipped to the image.
      const double x0 = bx * block_size - 0.5, y0 = by * block_size - 0.5;
      const double x1 = std::min<double>(width, (bx + 1) * block_size) - 0.5;
      const double y1 = std::min<double>(height, (by + 1) * block_size) - 0.5;
      for (const cv::Point2d& p : {cv::Point2d(x0, y0), cv::Point2d(x1, y0), cv::Point2d(x0, y1), cv::Point2d(x1, y1)}) {
        const double a = line.across(p), l = line.along(p);
        if (!box.valid) {
          box.across_min = box.across_max = a;
          box.along_min = box.along_max = l;
          box.valid = true;
        }
        box.across_min = std::min(box.across_min, a);
        box.across_max = std::max(box.across_max, a);
        box.along_min = std::min(box.along_min, l);
        box.along_max = std::max(box.along_max, l);
      }
    }
  }
  if (box.valid) {
    box.corners = {line.at(box.across_min, box.along_min), line.at(box.across_max, box.along_min),
                   line.at(box.across_max, box.along_max), line.at(box.across_min, box.along_max)};
  }
  return box;
}

}  // namespace nudge::tracking
