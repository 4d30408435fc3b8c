#pragma once
// The frame of a symmetry line, in which the line is vertical (see segment.hpp).
#include <opencv2/core.hpp>

#include <cmath>

#include "nudge/symmetry/line.hpp"

namespace nudge::segmentation::detail {

struct LineFrame {
  cv::Point2d centre, normal, direction;
  double r = 0;

  LineFrame(const symmetry::Line& line, int width, int height)
      : centre(0.5 * (width - 1), 0.5 * (height - 1)),
        normal(std::cos(line.theta), std::sin(line.theta)),
        direction(-std::sin(line.theta), std::cos(line.theta)),
        r(line.r) {}

  // (u, v): signed offset from the line and position along it.
  cv::Point2d to_line(const cv::Point2d& p) const {
    const cv::Point2d q = p - centre;
    return {q.dot(normal) - r, q.dot(direction)};
  }
  cv::Point2d to_image(double u, double v) const { return centre + (r + u) * normal + v * direction; }
};

// Row range covered by a w x h image in the line frame: [first, last] of round(v).
inline void row_range(const LineFrame& frame, int width, int height, int* first, int* last) {
  double lo = 1e300, hi = -1e300;
  for (const cv::Point2d corner : {cv::Point2d(0, 0), cv::Point2d(width - 1, 0), cv::Point2d(0, height - 1),
                                   cv::Point2d(width - 1, height - 1)}) {
    const double v = frame.to_line(corner).y;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  *first = static_cast<int>(std::floor(lo));
  *last = static_cast<int>(std::ceil(hi));
}

}  // namespace nudge::segmentation::detail
