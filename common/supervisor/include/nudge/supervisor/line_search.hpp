#pragma once
// A target's symmetry line in a high-resolution still, found near where the calibration predicts it:
// the detector restricted to a few degrees about the predicted angle, the peak nearest the predicted
// R taken. The prediction alone is off by the triangulation's error (millimetres = pixels); motion
// segmentation wants the object's own line.
#include <opencv2/core.hpp>

#include <optional>

#include "nudge/symmetry/detector.hpp"

namespace nudge::supervisor {

struct LineSearchParams {
  double window_deg = 6;     // +- about the predicted angle
  double window_px = 30;     // largest |R - R_predicted| accepted, at the still's resolution
  int lines = 5;             // peaks examined
  double mirror_tolerance_deg = 15;  // mirror-consistent pairs (docs: clutter and texture)
};

// The detected line nearest the prediction within the windows, or nothing.
std::optional<symmetry::Line> find_line_near(const cv::Mat& image, const symmetry::Line& predicted,
                                             const LineSearchParams& params = {});

}  // namespace nudge::supervisor
