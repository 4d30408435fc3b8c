#pragma once
// Scoring a tracker against ground truth by one rule whatever kind of tracker it is (issue 15):
// every tracker is asked for its estimate of the object's centre line, and that line is compared
// with the true symmetry axis over the object's true extent in the image. A perfect symmetry
// tracker (the true axis) and a perfect box tracker (the true mask's box, upright object) both
// score about 0; how far a perfect box is from 0 on a tilted object is the box trackers' floor.
// The overlap (IoU) of a tracker's region with the true mask is the second, independent score.
//
//   const CentreLine est = centre_line_of_box(box);           // CSRT, KCF: vertical through the centre
//   const double px = centre_line_error(est, truth_bottom, truth_top);
//   const double iou = mask_iou(polygon_mask(corners, size), true_mask);
#include <opencv2/core.hpp>

#include <vector>

namespace nudge::tracking {

// A tracker's estimate of the object's centre line: a point on it and its direction.
struct CentreLine {
  cv::Point2d point;
  cv::Point2d direction{0, 1};  // need not be unit length; must not be zero
};

// The vertical line through the centre of an axis-aligned box (what a box tracker claims of an
// upright object: it is centred in the box). A box of pixels, as cv::boundingRect gives: it covers
// pixel centres x .. x + width - 1, so its centre is x + (width - 1) / 2.
CentreLine centre_line_of_box(const cv::Rect2d& box);
// The long axis of a rotated box through its centre (a square box: its height direction).
CentreLine centre_line_of_rotated_box(const cv::RotatedRect& box);
// The line (r, theta) of the thesis' polar form about the image centre ((w-1)/2, (h-1)/2):
// (x - cx) cos theta + (y - cy) sin theta = r.
CentreLine centre_line_of_polar(double r, double theta, cv::Size image);

// Mean distance (px) from `samples` evenly spaced points of the true axis segment
// [true_bottom, true_top] (the object's true extent along its axis, ends included) to the
// estimated line. 0 when the estimate is the true line; d when it is shifted by d across it.
// Throws std::invalid_argument for a zero direction or fewer than 2 samples.
double centre_line_error(const CentreLine& estimate, const cv::Point2d& true_bottom, const cv::Point2d& true_top,
                         int samples = 21);

// Intersection over union of two CV_8U masks of one size (non-zero = inside); 0 when both are
// empty. Throws std::invalid_argument when sizes or types differ.
double mask_iou(const cv::Mat& region, const cv::Mat& truth);

// A filled convex polygon (a box's corners in order) as a CV_8U mask of `size`, 255 inside.
cv::Mat polygon_mask(const std::vector<cv::Point2f>& corners, cv::Size size);

}  // namespace nudge::tracking
