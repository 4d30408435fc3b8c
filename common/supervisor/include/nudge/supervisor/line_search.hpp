#pragma once
// A target's symmetry line in a high-resolution still, found near where the calibration predicts it:
// the detector restricted to a few degrees about the predicted angle, the peak nearest the predicted
// R taken. The prediction alone is off by the triangulation's error (millimetres = pixels); motion
// segmentation wants the object's own line.
//
// An object's line stands on the table: the edge pairs that voted for it reach down to its foot.
// A line in the window whose support ends well above the predicted foot is something standing
// behind the object or above it (the arm's base column, seen over a bottle that stood in front of
// it, outvoted the moved bottle's own line in a held-out run): lines that reach the foot are
// preferred, the nearest of them taken.
#include <opencv2/core.hpp>

#include <optional>

#include "nudge/symmetry/detector.hpp"

namespace nudge::supervisor {

struct LineSearchParams {
  double window_deg = 6;     // +- about the predicted angle
  double window_px = 30;     // largest |R - R_predicted| accepted, at the still's resolution
  int lines = 5;             // peaks examined
  double mirror_tolerance_deg = 15;  // mirror-consistent pairs (docs: clutter and texture)
  // The edge pairs' widths, px at 640x480 (scaled to the still's): the thesis' Dmin and Dmax.
  double min_pair_width_px = 25, max_pair_width_px = 250;
  // A line reaches the foot when its support ends at most this fraction of the predicted axis'
  // length above the predicted foot (the axis is drawn up to the tallest object's height, so
  // 0.3 of it is a few centimetres of a short cup's height at most).
  double foot_slack = 0.3;
};

// The detected line nearest the prediction within the windows, of those that reach the predicted
// foot when any does, or nothing. The prediction's seg1 is its foot on the table and seg2 its top
// (SceneGeometry::right_axis_line); a prediction without that span (seg1 == seg2) prefers no line.
std::optional<symmetry::Line> find_line_near(const cv::Mat& image, const symmetry::Line& predicted,
                                             const LineSearchParams& params = {});

}  // namespace nudge::supervisor
