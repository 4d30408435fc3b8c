// The whole of thesis sec. 4.2: SEPT, DP contour, refinement, back to image coordinates.
#include <cmath>
#include <stdexcept>

#include "line_frame.hpp"
#include "nudge/segmentation/segment.hpp"

namespace nudge::segmentation {

namespace {

// The nearest edge pixel within `radius` of p, or p itself when there is none (refinement step:
// the DP contour lies on half-width cells, up to MAXmid off the real edge pixels).
cv::Point2d snap_to_edge(const cv::Mat& edge_mask, const cv::Point2d& p, double radius) {
  const int reach = static_cast<int>(std::ceil(radius));
  const int px = static_cast<int>(std::lround(p.x)), py = static_cast<int>(std::lround(p.y));
  double best = radius * radius;
  cv::Point2d nearest = p;
  bool found = false;
  for (int y = std::max(0, py - reach); y <= std::min(edge_mask.rows - 1, py + reach); ++y) {
    const uint8_t* row = edge_mask.ptr<uint8_t>(y);
    for (int x = std::max(0, px - reach); x <= std::min(edge_mask.cols - 1, px + reach); ++x) {
      if (!row[x]) continue;
      const double d2 = (x - p.x) * (x - p.x) + (y - p.y) * (y - p.y);
      if (d2 <= best) {
        best = d2;
        nearest = cv::Point2d(x, y);
        found = true;
      }
    }
  }
  return found ? nearest : p;
}

cv::Mat mask_of(const symmetry::EdgeSet& edges) {
  cv::Mat mask = cv::Mat::zeros(edges.height, edges.width, CV_8U);
  for (const cv::Point& p : edges.points) {
    if (p.x >= 0 && p.y >= 0 && p.x < edges.width && p.y < edges.height) mask.at<uint8_t>(p) = 255;
  }
  return mask;
}

}  // namespace

Segmenter::Segmenter(SegmentParams params) : params_(params) { validate(params_); }

Contour Segmenter::segment(const symmetry::EdgeSet& edges, const symmetry::Line& line) const {
  const SeptBuffer buffer = sept(edges, line);
  Contour contour;
  contour.cells = best_path(buffer.weights, &contour.score);
  if (contour.cells.empty()) return contour;

  const detail::LineFrame frame(line, edges.width, edges.height);
  const cv::Mat edge_mask = params_.refine ? mask_of(edges) : cv::Mat();
  auto place = [&](double u, double v) {
    const cv::Point2d p = frame.to_image(u, v);
    return params_.refine ? snap_to_edge(edge_mask, p, params_.max_mid) : p;
  };
  for (const Cell& cell : contour.cells) {
    const double v = buffer.first_row + cell.row;
    contour.left.push_back(place(-cell.column, v));
    contour.right.push_back(place(cell.column, v));
  }
  return contour;
}

Contour Segmenter::segment(const cv::Mat& edge_mask, const symmetry::Line& line) const {
  if (edge_mask.empty() || edge_mask.type() != CV_8UC1)
    throw std::invalid_argument("segmentation: the edge mask must be a non-empty 8-bit single-channel image");
  return segment(symmetry::edges_from_mask(edge_mask), line);
}

Contour segment(const symmetry::EdgeSet& edges, const symmetry::Line& line, const SegmentParams& params) {
  return Segmenter(params).segment(edges, line);
}

Contour segment(const cv::Mat& edge_mask, const symmetry::Line& line, const SegmentParams& params) {
  return Segmenter(params).segment(edge_mask, line);
}

std::vector<cv::Point2d> Contour::polygon() const {
  std::vector<cv::Point2d> points(left.begin(), left.end());
  points.insert(points.end(), right.rbegin(), right.rend());
  return points;
}

}  // namespace nudge::segmentation
