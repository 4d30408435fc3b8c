#pragma once
// Symmetry-guided object contour segmentation (Li 2008, sec. 4.2, Algorithms 2-4).
//
// The edge pixels are expressed in the frame of the symmetry line, where the line is vertical:
//   u = (p - c).n - R   signed offset from the line (the "column", 0 on the line),
//   v = (p - c).d       position along the line (the "row"),
// with c the image centre, n = (cos theta, sin theta) the line's normal and d = (-sin theta, cos theta)
// its direction (for theta = 0, v grows downwards like image rows). Rows are round(v).
//
// Pipeline: SEPT (Alg. 2) -> dynamic-programming score table (Alg. 3) -> backtracking (Alg. 4)
// -> snapping onto the nearest edge pixel within MAXmid -> back to image coordinates.
#include <opencv2/core.hpp>

#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::segmentation {

struct SegmentParams {
  double max_width = 250;     // MAXw, px: widest edge pair considered (thesis: usually Dmax)
  double max_mid = 3;         // MAXmid, px: largest midpoint deviation from the line ("a few px")
  double reward_vertical = 1.0;     // Rver: reward per row of symmetric contour, times the SEPT weight
  double penalty_vertical = -0.5;   // Pver: score change per row crossing an empty cell (a gap)
  double reward_horizontal = 0.5;   // Rhor < Rver, so tall contours beat wide flat ones
  double penalty_horizontal = -0.5; // Phor: score change per empty cell crossed sideways
  bool refine = true;         // snap contour points onto the nearest edge pixel within max_mid
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const SegmentParams& params);

// The SEPT buffer (Alg. 2): rows along the line, columns = half-widths ceil(w/2) in 0..max_width/2.
struct SeptBuffer {
  cv::Mat weights;      // CV_32F, rows x columns; -1 = no symmetric pair
  int first_row = 0;    // row index 0 <-> v = first_row
  long long num_pairs = 0;  // edge pairs formed (the thesis' "number of edge pixel pairs")
};

// One cell of the contour in the line frame: row index into the SEPT buffer and half-width column.
struct Cell {
  int row = 0, column = 0;
};

struct Contour {
  // Both sides, ordered along the line (increasing v), in image coordinates.
  std::vector<cv::Point2d> left;   // the side at u < 0 (towards -normal)
  std::vector<cv::Point2d> right;  // the side at u > 0 (towards +normal)
  std::vector<Cell> cells;         // the DP path, first row first
  double score = 0;                // the DP score at the path's end (0: nothing found)
  bool empty() const { return cells.empty(); }
  // Closed polygon: left side along the line, right side back.
  std::vector<cv::Point2d> polygon() const;
};

class Segmenter {
 public:
  explicit Segmenter(SegmentParams params = {});
  const SegmentParams& params() const { return params_; }

  // The most continuous symmetric contour about `line`. Throws std::invalid_argument for an
  // empty edge set. An edge set without symmetric pairs gives an empty contour.
  Contour segment(const symmetry::EdgeSet& edges, const symmetry::Line& line) const;
  Contour segment(const cv::Mat& edge_mask, const symmetry::Line& line) const;  // 8-bit, non-zero = edge

  // The pieces, for tests and pictures.
  SeptBuffer sept(const symmetry::EdgeSet& edges, const symmetry::Line& line) const;
  std::vector<Cell> best_path(const cv::Mat& sept_weights, double* score = nullptr) const;

 private:
  SegmentParams params_;
};

// Convenience wrappers around Segmenter.
Contour segment(const symmetry::EdgeSet& edges, const symmetry::Line& line, const SegmentParams& params = {});
Contour segment(const cv::Mat& edge_mask, const symmetry::Line& line, const SegmentParams& params = {});

// Pictures: the contour (both sides, thick) and the line over a background; the SEPT buffer as grey.
cv::Mat draw_contour(const cv::Mat& background, const Contour& contour, const symmetry::Line& line,
                     const cv::Scalar& colour = cv::Scalar(0, 0, 255));
cv::Mat sept_image(const SeptBuffer& sept);
// Filled 8-bit mask (255 inside) of the contour's polygon.
cv::Mat contour_mask(const Contour& contour, cv::Size size);

}  // namespace nudge::segmentation
