#pragma once
// Block motion detection (Li 2008, sec. 5.2.2, Algorithm 5).
//
// |I1 - I0| summed in SB x SB blocks; a block moves when its sum exceeds TM x the mean block sum;
// the binary block image (IRES) is median filtered and dilated, then scaled up by SB to the motion
// mask (IMASK), which is ANDed with the edge image so that static background cannot vote.
#include <opencv2/core.hpp>

namespace nudge::tracking {

struct BlockMotionParams {
  int block_size = 8;             // SB, px (thesis: 8)
  double threshold_factor = 1.5;  // TM, multiple of the mean block sum (thesis: 1.5)
  // Not in the thesis: a block must also differ by this many grey levels per pixel on average.
  // Without it, two frames that differ only by sensor noise (or a single moving pixel) still
  // give "moving" blocks, because the threshold is relative to the mean. 0 = Algorithm 5 as published.
  double min_mean_difference = 1.0;
  int median_size = 3;            // median filter of IRES, blocks (odd); 1 = none
  int dilate_size = 3;            // dilation of IRES, blocks (odd); 1 = none
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const BlockMotionParams& params);

struct BlockMotion {
  int block_size = 8;
  cv::Mat block_sums;   // CV_32F, blocks_h x blocks_w: difference sums scaled to a full block
  cv::Mat moving;       // CV_8U 0/1, after threshold only (before median and dilation)
  cv::Mat blocks;       // CV_8U 0/1, IRES: thresholded, median filtered, dilated
  int moving_blocks = 0;// non-zero blocks of `moving` after the median filter (the start detector's signal)
  int blocks_w() const { return blocks.cols; }
  int blocks_h() const { return blocks.rows; }
};

// Blocks cover the image; the last row / column of blocks may be partial (its sum is scaled up to a
// full block so that it is judged like the others). Both frames must be 8-bit grey of equal size.
// Throws std::invalid_argument otherwise.
BlockMotion detect_block_motion(const cv::Mat& previous, const cv::Mat& current,
                                const BlockMotionParams& params);

// IMASK: a block image scaled up by block_size and cropped to width x height (CV_8U, 0/255).
cv::Mat upscale_blocks(const cv::Mat& blocks, int block_size, int width, int height);

// The edge pixels of an 8-bit edge image that lie inside a motion mask of the same size.
cv::Mat mask_edges(const cv::Mat& edges, const cv::Mat& motion_mask);

}  // namespace nudge::tracking
