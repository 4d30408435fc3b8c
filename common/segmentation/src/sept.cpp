// Symmetric edge pair transform (thesis Algorithm 2).
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "line_frame.hpp"
#include "nudge/segmentation/segment.hpp"

namespace nudge::segmentation {

namespace {
void require(bool ok, const std::string& message) {
  if (!ok) throw std::invalid_argument(message);
}
}  // namespace

void validate(const SegmentParams& p) {
  require(std::isfinite(p.max_width) && p.max_width >= 2 && p.max_width <= 1e5,
          "segmentation parameter max_width (MAXw) must be in [2, 1e5] px");
  require(std::isfinite(p.max_mid) && p.max_mid > 0 && p.max_mid <= 100,
          "segmentation parameter max_mid (MAXmid) must be in (0, 100] px");
  require(std::isfinite(p.reward_vertical) && p.reward_vertical > 0,
          "segmentation parameter reward_vertical (Rver) must be > 0");
  require(std::isfinite(p.reward_horizontal) && p.reward_horizontal > 0 && p.reward_horizontal < p.reward_vertical,
          "segmentation parameter reward_horizontal (Rhor) must satisfy 0 < Rhor < Rver");
  require(std::isfinite(p.penalty_vertical) && p.penalty_vertical < 0,
          "segmentation parameter penalty_vertical (Pver) must be < 0");
  require(std::isfinite(p.penalty_horizontal) && p.penalty_horizontal < 0,
          "segmentation parameter penalty_horizontal (Phor) must be < 0");
}

SeptBuffer Segmenter::sept(const symmetry::EdgeSet& edges, const symmetry::Line& line) const {
  if (edges.width <= 0 || edges.height <= 0) throw std::invalid_argument("segmentation: edge set is empty");
  const detail::LineFrame frame(line, edges.width, edges.height);
  int first = 0, last = 0;
  detail::row_range(frame, edges.width, edges.height, &first, &last);

  // Rotate the edge pixels so the line is vertical, one list of offsets u per row.
  std::vector<std::vector<double>> offsets(static_cast<size_t>(last - first + 1));
  for (const cv::Point& p : edges.points) {
    if (p.x < 0 || p.y < 0 || p.x >= edges.width || p.y >= edges.height) continue;  // not in this image
    const cv::Point2d uv = frame.to_line(cv::Point2d(p.x, p.y));
    offsets[static_cast<size_t>(std::lround(uv.y) - first)].push_back(uv.x);
  }

  const int columns = static_cast<int>(std::ceil(params_.max_width / 2)) + 1;
  SeptBuffer sept;
  sept.first_row = first;
  sept.weights = cv::Mat(last - first + 1, columns, CV_32F, cv::Scalar(-1));
  for (size_t row = 0; row < offsets.size(); ++row) {
    std::vector<double>& u = offsets[row];
    std::sort(u.begin(), u.end());
    float* cells = sept.weights.ptr<float>(static_cast<int>(row));
    for (size_t i = 0; i < u.size(); ++i) {
      for (size_t j = i + 1; j < u.size(); ++j) {
        const double width = u[j] - u[i];
        if (width > params_.max_width) break;  // sorted: every later partner is wider still
        ++sept.num_pairs;
        const double deviation = std::fabs(0.5 * (u[i] + u[j]));
        if (deviation >= params_.max_mid) continue;
        const int column = std::max(1, static_cast<int>(std::ceil(0.5 * width)));
        const float weight = static_cast<float>(1.0 - deviation / (2.0 * params_.max_mid));
        // Overlapping pairs of equal width share a cell: the more symmetric one wins.
        if (column < columns && cells[column] < weight) cells[column] = weight;
      }
    }
  }
  return sept;
}

}  // namespace nudge::segmentation
