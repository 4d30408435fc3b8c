#pragma once
// A target's symmetry line in a high-resolution still, found near where the calibration predicts it:
// the detector restricted to a few degrees about the predicted angle and a few pixels about the
// predicted R, the strongest peak there taken. The prediction alone is off by the triangulation's
// error (millimetres = pixels); motion segmentation wants the object's own line.
//
// An object's line stands on the table: the edge pairs that voted for it reach down to its foot.
// A line in the window whose support ends well above the predicted foot is something standing
// behind the object or above it (the arm's base column, seen over a bottle that stood in front of
// it, outvoted the moved bottle's own line in a held-out run): lines that reach the foot are
// preferred, the strongest of them taken.
#include <opencv2/core.hpp>

#include <optional>
#include <vector>

#include "nudge/symmetry/detector.hpp"

namespace nudge::supervisor {

struct LineSearchParams {
  double window_deg = 6;     // +- about the predicted angle
  double window_px = 30;     // largest |R - R_predicted| accepted, at the still's resolution
  // Peaks examined. The band about the prediction holds the neighbours' lines too (edge pairs up
  // to max_pair_width_px wide): in a multi-object scene five peaks were often all theirs.
  int lines = 10;
  double mirror_tolerance_deg = 15;  // mirror-consistent pairs (docs: clutter and texture)
  // The edge pairs' widths, px at 640x480 (scaled to the still's): the thesis' Dmin and Dmax.
  double min_pair_width_px = 25, max_pair_width_px = 250;
  // A line reaches the foot when its support ends at most this fraction of the predicted axis'
  // length above the predicted foot (the axis is drawn up to the tallest object's height, so
  // 0.3 of it is a few centimetres of a short cup's height at most).
  double foot_slack = 0.3;
  // Run the detector only on the part of the still that the accepted lines' edge pairs can lie in
  // (search_region): the windows above, the pair widths and the predicted axis' span. The lines
  // found are the same lines (in the whole still's coordinates); the still's other edges are
  // neither detected nor voted with, which was most of the search's time in a 1280x960 still.
  bool crop_to_prediction = true;
  // Of the lines in the windows (those reaching the foot first when any does), the one with the
  // most votes rather than the one nearest the prediction. The prediction is off by the
  // triangulation's error; a faint line (an object's edge paired with the arm's base column
  // behind it) can lie nearer it than the object's own strong one.
  bool strongest = true;
  // find_moved_line: the after still's line is searched first within this many degrees of the
  // before line's lean carried over to the rest (0: not; the window_deg search alone).
  double lean_window_deg = 2;
  // A found line within this many px (at the still's resolution) and degrees of one of the
  // not-an-object lines given to the search (the arm's base column's axis, projected) is that
  // thing's, not the object's: an object standing in front of the column in the image shows the
  // column's line beside its own, often stronger and reaching down to the object's foot.
  double not_object_px = 8, not_object_deg = 1.5;
  // With an earlier still given to the search: a line about which less than this share of the
  // pixels changed (changed_share: Dmin/2 either side, along its support, by more than
  // change_threshold grey levels in a channel) stood there already, not the pushed object
  // arriving. A symmetry count would not tell: a checkered table gives any line there hundreds
  // of voting pairs in either still (held-out h11: the moved bottle's line 849 pairs after, 477
  // before).
  double min_changed_share = 0.15;
  int change_threshold = 25;
};

// The share of the pixels within `half_width_px` of `line` (along its support seg1-seg2; the whole
// image's span of it when it has none) whose colour differs between two stills of the same view
// by more than `threshold` in some channel. 0 for stills of different sizes or types.
double changed_share(const cv::Mat& earlier, const cv::Mat& later, const symmetry::Line& line, double half_width_px,
                     int threshold);

// The part of a `size` image a search for lines near `predicted` needs: the band about the predicted
// axis' span (seg1 to seg2, lengthened by params.window_px at both ends) that holds every edge pair of
// a line within the windows, widths up to max_pair_width_px (scaled to the image's width). The whole
// image for a prediction without a span.
cv::Rect search_region(const cv::Size& size, const symmetry::Line& predicted, const LineSearchParams& params = {});


// The strongest detected line within the windows (the nearest with params.strongest off), of those
// that reach the predicted foot when any does, or nothing. The prediction's seg1 is its foot on the table and seg2 its top
// (SceneGeometry::right_axis_line); a prediction without that span (seg1 == seg2) prefers no line.
// Lines agreeing with one of `not_objects` (params.not_object_px, not_object_deg) are passed over,
// unless the prediction agrees with it too (the object in line with it). With `earlier` (a still
// of the same view, the same size and type, taken before; std::invalid_argument otherwise), a line
// about which too little changed since then stood there and is passed over wherever the
// prediction lies (params.min_changed_share).
std::optional<symmetry::Line> find_line_near(const cv::Mat& image, const symmetry::Line& predicted,
                                             const LineSearchParams& params = {},
                                             const std::vector<symmetry::Line>& not_objects = {},
                                             const cv::Mat& earlier = cv::Mat());

// The nudged object's line in the still after the nudge. An object that slid and stayed upright
// keeps its lean: its line leans from the calibration's prediction at its rest (an upright axis)
// as much as `before_line` (the object's line found in the before still) leaned from the
// prediction at its start. Lines within params.lean_window_deg of that are searched for first
// (find_line_near about the prediction turned by the lean about its foot); then, when none is
// found or no before line is known, the whole window_deg about `predicted_after` (a push that
// changed the lean; a tipped object is the settling check's to refuse).
std::optional<symmetry::Line> find_moved_line(const cv::Mat& after, const symmetry::Line& predicted_after,
                                              const symmetry::Line& predicted_before,
                                              const std::optional<symmetry::Line>& before_line,
                                              const LineSearchParams& params = {},
                                              const std::vector<symmetry::Line>& not_objects = {},
                                              const cv::Mat& earlier = cv::Mat());

// `predicted` turned by `angle` (radians, the (R, theta) convention's sense) about its seg1, its
// span turned with it.
symmetry::Line turned_about_foot(const symmetry::Line& predicted, double angle, const cv::Size& size);

}  // namespace nudge::supervisor
