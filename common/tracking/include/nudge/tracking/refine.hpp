#pragma once
// Symmetry-refined motion mask and rotated bounding box (Li 2008, sec. 5.2.3, fig. 5.3-5.6).
//
// Works on the block image IRES (one cell per SB x SB block), so refinement costs 1/SB^2 of a
// pixel-wise pass. Both steps are single passes, as in the thesis (no iteration).
#include <opencv2/core.hpp>

#include <array>

namespace nudge::tracking {

struct RefineParams {
  int mirror_window = 1;        // half-size, blocks, of the window searched around a block's mirror image
  int fill_window = 1;          // half-size, blocks, of the neighbourhood used to fill holes
  int fill_min_neighbours = 5;  // a static block becomes moving with at least this many moving neighbours
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const RefineParams& params);

// 1. Drops each moving block whose mirror image across the line (r px, theta rad, about the image
//    centre) has no moving block within mirror_window. 2. Marks a block moving when at least
//    fill_min_neighbours blocks of its (2 fill_window + 1)^2 neighbourhood moved after step 1.
// blocks: CV_8U 0/1 (IRES); width/height: the image the blocks cover.
cv::Mat refine_blocks(const cv::Mat& blocks, int block_size, int width, int height, double r, double theta,
                      const RefineParams& params);

// Rectangle around every moving block with two sides parallel to the line (r px, theta rad).
struct RotatedBox {
  bool valid = false;               // false when no block moves
  std::array<cv::Point2d, 4> corners;  // image px, in order around the box
  double across_min = 0, across_max = 0;  // signed distance from the line along its normal, px
  double along_min = 0, along_max = 0;    // position along the line from its pivot, px
};
RotatedBox rotated_box(const cv::Mat& blocks, int block_size, int width, int height, double r, double theta);

}  // namespace nudge::tracking
