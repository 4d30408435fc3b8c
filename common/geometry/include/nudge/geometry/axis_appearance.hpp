#pragma once
// Whether the two cameras see the same thing along a triangulated axis (issue 14). An object's
// axis runs inside the object: at each height both cameras look at its near surface and see about
// the same colour. A phantom pairing (one object's line in the left image with another's, or with
// a line between two objects, in the right) puts its axis where the two views show different
// things. Images are the ones the lines were found in.
#include <opencv2/core.hpp>

#include "nudge/geometry/outcome.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/triangulation.hpp"

namespace nudge::geometry {

struct AxisAppearanceParams {
  double lowest_m = 0.01;        // first height above the table looked at (the foot's shadow below)
  double step_m = 0.005;         // between heights
  int window_px = 1;             // colours are the mean of a (2 w + 1)^2 window
  double colour_tolerance = 60;  // L1 over BGR (0-765): the same colour
  int min_samples = 3;           // fewer heights in both images: no verdict
};

// Throws std::invalid_argument naming the offending parameter.
void validate(const AxisAppearanceParams& params);

// The share of heights from params.lowest_m to `top_m` above the table, along `axis` from its table
// hit (right camera frame), whose projections into the left and right images have the same
// colour. Fails when fewer than min_samples heights project into both images, or the images are
// not 8-bit BGR or grey of the rig's sizes.
Outcome<double> axis_colour_agreement(const StereoRig& rig, const cv::Mat& left_image, const cv::Mat& right_image,
                                      const Segment3& axis, const Eigen::Vector3d& table_hit, const Plane& table,
                                      double top_m, const AxisAppearanceParams& params = {});

}  // namespace nudge::geometry
