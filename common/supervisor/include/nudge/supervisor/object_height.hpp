#pragma once
// How tall a candidate stands, from the right camera's still before the nudge. The arm's planner
// keeps the forearm and wrist clear of the pushed object; not knowing the object, it assumes the
// tallest one expected (robot::NudgeParams::object_height, 0.25 m), and near the workspace ring's
// edge that refuses pushes a 0.20 m bottle leaves room for. Measured, the push can clear the object
// it meets rather than the tallest one there might be.
//
// The measurement is built to err high: the top is the highest edge pair symmetric about the
// object's line (with pairs narrow enough for a bottle's neck and cap), and the ray through it is
// read where it passes above the object's axis, which for a top seen from above is the rear rim
// (r tan(theta) higher than the top). Symmetric clutter above the object raises it further. Only
// an object whose top has no edge pair at all (a clear cap against a clear background) reads low,
// which the margin the supervisor adds is for.
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>

#include "nudge/supervisor/scene.hpp"
#include "nudge/symmetry/detector.hpp"

namespace nudge::supervisor {

struct HeightParams {
  // Narrowest edge pair counted, px at 640x480 (the still's are scaled): a bottle's cap, 25 mm
  // across at 0.7 m, is 20 px there; the survey's 25 px leaves it out.
  double min_pair_width_px = 6;
  double max_pair_width_px = 250;  // at 640x480, as the survey's
  double window_deg = 2;           // the line searched within +- this of the object's line
  double window_px = 4;            // ... and this far of it (at 640x480)
  double margin_m = 0.02;          // added to the measured top before the arm is told
};

// Throws std::invalid_argument naming the parameter.
void validate(const HeightParams& params);

// The height above the table at which the right camera's ray through `pixel` (at image `size`)
// passes over the vertical through `foot` (world; the ray's point nearest it seen from above).
// Nothing when the pixel does not map to a ray or the ray runs parallel to the vertical.
std::optional<double> ray_height_over(const SceneGeometry& scene, const Eigen::Vector3d& foot, const cv::Point2d& pixel,
                                      cv::Size size);

// The table point (world, z = 0) under the lower end of `line`'s support in the right camera
// (image `size`): where the ray through it meets the table. Nothing for a line without support, or
// when that ray does not meet the table in front of the camera.
std::optional<Eigen::Vector3d> table_point_under_line_foot(const SceneGeometry& scene, const symmetry::Line& line,
                                                           cv::Size size);

// How far `foot` (world: an axis standing on the table) lies beyond the table point under the
// lower end of `line`'s support in the right camera (image `size`), along the camera's horizontal
// view towards `foot`, m. The lowest pixel of an upright object's outline is the front of its
// base: for the object's own axis this is about its radius (0 to 5 cm); for a candidate that a
// stereo mismatch placed at another depth on the same right-camera line, it is off by the
// mismatch. Nothing for a line without support, or when the ray through the lower end does not
// meet the table in front of the camera.
std::optional<double> depth_beyond_line_foot(const SceneGeometry& scene, const symmetry::Line& line,
                                             const Eigen::Vector3d& foot, cv::Size size);

// The object's height in the right still: the top of the edge pairs symmetric about
// `object_line` (its line in the still, e.g. find_line_near's), read over the vertical through
// `foot`, and never below the top of `object_line`'s own support. Nothing when no line near
// `object_line` is found or its top does not map to a height.
std::optional<double> measure_object_height(const SceneGeometry& scene, const cv::Mat& right_still,
                                            const symmetry::Line& object_line, const Eigen::Vector3d& foot,
                                            const HeightParams& params = {});

}  // namespace nudge::supervisor
