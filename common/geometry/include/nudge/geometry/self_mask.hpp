#pragma once
// The robot's own body in the cameras (a robot self-filter): the arm's base column stands where
// the calibration says (arm_base, on the table), upright, symmetric and always in view. Its edges
// vote for a strong symmetry line that, with an object standing in line with it, absorbs the
// object's line or pairs with it across the cameras (docs/supervisor.md, "Measured"). Its image
// region, known from the calibration, is left out of the edges the detector votes with.
#include <opencv2/core.hpp>

#include <vector>

#include <Eigen/Core>

#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/stereo_pairing.hpp"
#include "nudge/geometry/stereo_rig.hpp"

namespace nudge::geometry {

// A vertical cylinder standing on the table: its foot (any point on its axis; moved onto the
// table), radius and height above the table, m. Right camera frame, as everywhere in the rig.
struct Column {
  Eigen::Vector3d foot = Eigen::Vector3d::Zero();
  double radius = 0.065;
  double height = 0.4;
};

// The column's pixels in `side`'s image (255 inside, widened by margin_px), the size of that
// camera's image: the filled outline of points sampled on its surface. Empty (all 0) when the
// column is behind the camera. Throws std::invalid_argument for a non-positive radius or height,
// or a negative margin.
cv::Mat column_mask(const StereoRig& rig, Side side, const Plane& table, const Column& column, int margin_px = 4);

// The band of a region's outline, band_px either side of it: the column's votes come from pairs
// of its two silhouette edges, while an object standing in front of it has its own edges inside
// the region, which the whole region would take away too. Throws std::invalid_argument for a
// band < 1 px or a mask that is not 8-bit single channel.
cv::Mat outline_band(const cv::Mat& region, int band_px);

// What to leave out of `side`'s edges for several columns: with band_px > 0 the union of their
// outline bands, else the union of their regions widened by margin_px. Empty columns: all 0.
// Throws as column_mask and outline_band do.
cv::Mat columns_mask(const StereoRig& rig, Side side, const Plane& table, const std::vector<Column>& columns,
                     int margin_px, int band_px);

}  // namespace nudge::geometry
