#pragma once
// Object segmentation by motion (Li 2008, sec. 6.4, fig. 6.7).
//
// Inputs: one camera's images before and after a nudge and the object's symmetry line in each
// ((R, theta) about the image centre, symmetry/detector.hpp). Steps:
//   (c) difference   |after - before| (largest change over the colour channels), minus its median
//                    (the noise floor: sensor noise, lighting flicker);
//   (d) compressed   the difference in the frame of the lines, where they are vertical: the half
//                    on the leading side of the motion is taken beyond the AFTER line, the half on
//                    the trailing side beyond the BEFORE line, and the pixels between the lines are
//                    dropped, so the two lines merge into one (column max_half_width);
//   (e) refined      symmetric filling: in each row, a pair of pixels mirrored about the merged
//                    line is as strong as its weaker side, and every pixel gets the strongest
//                    pair at or beyond it. Motion whose mirror did not move (an arm, a hand,
//                    another object) does not count;
//   threshold        (e) >= threshold, rows shorter than min_vertical_run dropped, gaps up to
//                    max_row_gap rows bridged, the largest run of rows kept: the object's mask in
//                    the line frame;
//   (f) result       the mask placed at the object's AFTER position, plus the asymmetric parts
//                    attached to it that moved rigidly with the lines (a mug's handle; an arm that
//                    appeared in the after image does not), and the after image cut out.
#include <opencv2/core.hpp>

#include <string>

#include "nudge/symmetry/detector.hpp"

namespace nudge::segmentation {

struct MotionParams {
  // Grey levels (0-255) above the noise floor a mirrored pair of pixels must both exceed to count
  // as the object's motion. The object's contrast against its background has to exceed it.
  double threshold = 15;
  // Subtract the difference image's median (the change most pixels show: noise, flicker) first.
  bool subtract_noise_floor = true;
  // Gaussian blur of the compressed difference, px; 0 = none. Removes single-pixel noise.
  double blur_sigma = 1.0;
  // Widest object half-width considered, px: the compressed image is 2 * max_half_width + 1 wide.
  int max_half_width = 300;
  // A moving pixel pairs with motion within this many px of its mirror image (the lines' error).
  int mirror_tolerance = 1;
  // Rows of the mask must be part of a vertical run at least this long (opening along the line):
  // rows lengthened by a chance pair of noisy pixels far out are cut back. 1 = off.
  int min_vertical_run = 5;
  // Gaps along the line up to this many rows are bridged (closing along the line): rows where the
  // object's outline does not contrast with the background (a stripe the background's colour)
  // take their neighbours' width. 0 = off.
  int max_row_gap = 15;
  // Fewer mask pixels than this: no object found (no motion, or too little of it).
  int min_area = 100;
  // The lines' orientations may differ by at most this much (the object turned in the image).
  double max_rotation_deg = 20;
  // Asymmetric parts (a mug's handle): add the pixels within attach_reach px of the symmetric
  // mask's box, connected to it, that moved rigidly with the lines: changed here, outside the
  // symmetric mask moved back to the before position (the strip the object uncovered), and the
  // after image here matches the before image where the lines' motion says the point came from,
  // within rigid_tolerance grey levels (an arm that appeared does not).
  bool attach_rigid_parts = true;
  int attach_reach = 100;
  double rigid_tolerance = 30;
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const MotionParams& params);

// Fig. 6.7's images, filled on request. The line-frame images are rotated so that the merged line
// is vertical (column max_half_width); row 0 is `first_row` px along the line from its point
// nearest the image centre.
struct MotionStages {
  cv::Mat before, after;     // (a), (b) the inputs
  cv::Mat difference;        // (c) CV_8U, image frame, noise floor not yet subtracted
  cv::Mat compressed;        // (d) CV_8U, line frame, noise floor subtracted, blurred
  cv::Mat refined;           // (e) CV_8U, line frame, symmetric filling
  cv::Mat line_frame_mask;   // (e) thresholded, cleaned: CV_8U, 255 = object (the symmetric part)
  cv::Mat mask;              // CV_8U, after image frame, 255 = object (attached parts included)
  cv::Mat cutout;            // (f) the after image where mask, 0 elsewhere
  symmetry::Line line_before, line_after;
  int first_row = 0;
  int noise_floor = 0;       // grey levels subtracted

  // Writes the stages as PNGs into `directory` (created if missing): a_before.png, b_after.png,
  // c_difference.png (with the lines: before green, after red), d_compressed.png, e_refined.png,
  // e_mask_line_frame.png, f_segmentation.png, mask.png. Throws std::runtime_error naming the file
  // that could not be written; std::logic_error if the stages are empty.
  void save(const std::string& directory) const;
};

struct MotionSegmentation {
  bool found = false;   // a mask of at least min_area pixels
  std::string reason;   // why not, when !found
  cv::Mat mask;         // CV_8U, the after image's size, 255 = object (all 0 when !found)
  // (The cut-out is cut_out(after, mask): 3.7 MB of zeros at 1280x960 that only pictures need,
  // left out of the segmentation's time.)
  int area = 0;         // mask pixels
  cv::Rect bounding_box;
  // The after line's offset from the before line along its normal at its point nearest the image
  // centre, px (the motion), and the change of orientation, radians.
  double shift = 0;
  double rotation = 0;
};

namespace detail {
// The images MotionSegmenter reuses between calls.
struct MotionScratch {
  cv::Mat difference, compressed, blurred, dilated, refined;
  cv::Mat mirrored_blurred, mirrored_dilated, pairs, above_threshold;
};
}  // namespace detail

// Keeps its scratch images between calls (a 1280x960 pair allocates only its results after the
// first): one instance per thread.
class MotionSegmenter {
 public:
  explicit MotionSegmenter(MotionParams params = {});  // validates
  const MotionParams& params() const { return params_; }

  // `before`, `after`: the same size and type, 8-bit, 1 or 3 channels. The lines must cross the
  // image. Throws std::invalid_argument naming the bad input. `stages`, if given, gets fig. 6.7.
  MotionSegmentation segment(const cv::Mat& before, const cv::Mat& after, const symmetry::Line& line_before,
                             const symmetry::Line& line_after, MotionStages* stages = nullptr);

 private:
  MotionParams params_;
  detail::MotionScratch scratch_;
};

// Per pixel, the largest change of a channel between two 8-bit images of the same size and type
// (a change of hue counts as much as one of brightness): CV_8U. Vectorised for 1 and 3 channels.
// Throws std::invalid_argument for images that differ or are not 8-bit.
cv::Mat largest_channel_change(const cv::Mat& earlier, const cv::Mat& later);

// `image` where `mask` (8-bit, one channel, the image's size) is set, 0 elsewhere: fig. 6.7 (f).
// Throws std::invalid_argument for a mask that does not fit.
cv::Mat cut_out(const cv::Mat& image, const cv::Mat& mask);

// `image` reflected about `line` ((R, theta) about the image centre), same size and type; what
// falls outside is dropped, what nothing maps to is 0.
cv::Mat mirror_image(const cv::Mat& image, const symmetry::Line& line);

// How nearly a mask (8-bit, non-zero = object) is its own mirror image about `line` ((R, theta)
// about the image centre): the intersection over union of the mask and its reflection grown by
// one pixel, in [0, 1]; 0 for an empty mask. The mask of an upright, bilaterally symmetric object
// is mirrored about its symmetry line (above 0.79 in every correct segmentation of the
// development runs); a piece of one, a neighbour's edge or a toppled object's end is not. Throws
// std::invalid_argument for an empty image or one that is not 8-bit single-channel.
double mirror_agreement(const cv::Mat& mask, const symmetry::Line& line);

// How closely a mask's sides follow edges of the image it was cut from. A mask that is the object
// runs along the object's outline on both sides; one cut about a wrong line (the after line on a
// neighbour's edge or between two objects) ends on one side inside the object, where the image
// has no edge (development m02, 2026-12-03: half a red cup, IoU 0.37, its right side on an edge in
// 11 % of its rows; the development runs' masks of IoU 0.73 or more: 34 % or more on both sides).
struct SideEdgeParams {
  double blur_sigma = 1.0;             // Gaussian blur before Canny, px
  double canny_low = 20, canny_high = 60;  // on the grey image and on each colour channel
  int tolerance_px = 3;                // a side pixel this close to an edge pixel is on it
  double trim = 0.1;                   // the mask's top and bottom tenth (a lid, the foot's shadow) left out
};

// The smaller of the two sides' shares: over the mask's rows (trimmed), the share of rows whose
// leftmost mask pixel lies within tolerance_px of an edge, and likewise the rightmost; in [0, 1],
// 0 for an empty mask. The edges are found only around the mask's box. Throws
// std::invalid_argument for a mask that is not 8-bit single-channel, or an image (8-bit, 1 or 3
// channels) of another size.
double side_edge_support(const cv::Mat& mask, const cv::Mat& image, const SideEdgeParams& params = {});

// Clears the pixels of `mask` (8-bit, one channel) farther than `half_width_px` from `line`
// ((R, theta) about the image centre), measured along the line's normal; returns how many were
// cleared. Every part of an upright object lies within its widest half-width of its symmetry line:
// motion beyond that is something else that moved (a neighbour pushed along with the object and
// attached to its mask as a rigid part, an object that fell across the line). Throws
// std::invalid_argument for an empty mask, one that is not 8-bit single-channel, or a negative width.
int keep_near_line(cv::Mat& mask, const symmetry::Line& line, double half_width_px);

// One-shot convenience around MotionSegmenter.
MotionSegmentation segment_by_motion(const cv::Mat& before, const cv::Mat& after, const symmetry::Line& line_before,
                                     const symmetry::Line& line_after, const MotionParams& params = {},
                                     MotionStages* stages = nullptr);

}  // namespace nudge::segmentation
