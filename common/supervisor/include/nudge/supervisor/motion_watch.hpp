#pragma once
// Object motion during the nudge (thesis sec. 6.3.2): block motion (Alg. 5) between consecutive
// right-camera frames, counted only in a band beyond the target's symmetry line on the side the
// object is pushed towards. The end effector never crosses the line, so its own motion is not
// counted; a candidate that is a phantom (an axis between two objects) shows none.
#include <opencv2/core.hpp>

#include "nudge/symmetry/detector.hpp"
#include "nudge/tracking/block_motion.hpp"

namespace nudge::supervisor {

struct MotionWatchParams {
  tracking::BlockMotionParams blocks;
  double margin_px = 3;    // the band starts this far beyond the line (the line's own blocks are ambiguous)
  double band_px = 90;     // and is this wide (at 640x480: wider than the objects' half widths)
  int min_blocks = 3;      // moving blocks inside the band that make a frame "moving"
  int min_frames = 2;      // frames with motion that make the nudge "moved something"
};

class MotionWatch {
 public:
  // `line`: the target's symmetry line in the frames' coordinates; `push`: the image direction the
  // object is pushed along (only its side of the line matters); rows [top, bottom] bound the object.
  MotionWatch(const symmetry::Line& line, const cv::Point2d& push, int top, int bottom, cv::Size size,
              MotionWatchParams params = {});
  // The next frame (8-bit grey or BGR, the size given). Throws std::invalid_argument naming the size.
  void feed(const cv::Mat& frame);

  bool moved() const { return frames_with_motion_ >= params_.min_frames; }
  int frames_with_motion() const { return frames_with_motion_; }
  int max_blocks() const { return max_blocks_; }
  int frames() const { return frames_; }
  const cv::Mat& region() const { return region_; }  // CV_8U 0/255, one byte per block

 private:
  MotionWatchParams params_;
  cv::Size size_;
  cv::Mat region_;  // blocks whose centre lies in the watched band (0/255)
  cv::Mat region_ones_;  // the same as 0/1, to AND with the 0/1 moving flags
  cv::Mat in_band_;      // scratch: moving blocks in the band (kept between frames: no allocation)
  cv::Mat previous_;
  int frames_ = 0, frames_with_motion_ = 0, max_blocks_ = 0;
};

}  // namespace nudge::supervisor
