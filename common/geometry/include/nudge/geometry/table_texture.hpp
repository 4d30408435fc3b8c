#pragma once
// The table's own texture, told apart by stereo (issue 14, busy tables): a checkered or patterned
// table is full of edges that pair into symmetry lines, and those lines crowd the objects' out of
// the few the detector keeps. A point of the table's surface looks the same in both cameras at the
// places the table plane maps it to; an object standing on the table does not (its surface is above
// the plane, so the other camera sees it elsewhere, or sees the table behind it). So each camera's
// image is compared with the other camera's image warped through the table plane (a plane-induced
// homography, lens distortion included): where the two agree, the pixels are the table's, and their
// edges are left out of the voting. Objects keep their outlines; only the foot of an object, where it
// touches the table, agrees too.
#include <opencv2/core.hpp>

#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/stereo_pairing.hpp"
#include "nudge/geometry/stereo_rig.hpp"

namespace nudge::geometry {

// For every pixel of `to`'s image, where the point of the table plane seen there appears in the
// other camera's image (cv::remap maps, CV_32FC1). Pixels whose ray misses the table in front of
// both cameras (above the horizon, or the table behind the other camera) map to (-1, -1).
struct PlaneWarp {
  Side to = Side::Right;
  cv::Mat map_x, map_y;  // the size of `to`'s image
  cv::Size other_size;   // the other camera's image size
  cv::Size size() const { return map_x.size(); }
};
// Throws std::invalid_argument for a table plane with a zero normal.
PlaneWarp plane_warp(const StereoRig& rig, Side to, const Plane& table);

struct TableTextureParams {
  // Gaussian blur of both images before they are compared (0: none): the two views sample the
  // table at different scales, and the warp resamples one of them, so sharp texture differs by
  // a pixel's aliasing along every edge.
  double blur_sigma = 0.5;
  // Half-size of the square window the two images are compared over, px.
  int window_radius = 3;
  // Each pixel is compared with the best of the warped image's pixels this many px around it
  // (calibration error and the table's thickness shift the warp by a pixel or so).
  int search_px = 1;
  // Largest mean absolute grey difference over the window for the pixel to be the table's.
  double max_difference = 12.0;
  // Pixels within this many px of the image's border or of where the warp is undefined are
  // never the table's (the window would reach outside the other image).
  int margin_px = 2;
};
// Throws std::invalid_argument naming the offending field.
void validate(const TableTextureParams& params);

// 255 where `image` (the `warp.to` camera's, 8-bit grey or BGR) agrees with `other` (the other
// camera's image of the same moment) through the table plane: the table's own texture. Throws
// std::invalid_argument when either image is empty, of a type other than 8-bit 1 or 3 channels, or
// not the size the warp was made for.
cv::Mat table_texture_mask(const cv::Mat& image, const cv::Mat& other, const PlaneWarp& warp,
                           const TableTextureParams& params = {});

}  // namespace nudge::geometry
