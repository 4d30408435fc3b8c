#include "nudge/geometry/self_mask.hpp"

#include <opencv2/imgproc.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <stdexcept>
#include <vector>

namespace nudge::geometry {

cv::Mat column_mask(const StereoRig& rig, Side side, const Plane& table, const Column& column, int margin_px) {
  if (!(column.radius > 0) || !(column.height > 0))
    throw std::invalid_argument("column radius and height must be > 0");
  if (margin_px < 0) throw std::invalid_argument("column mask margin must be >= 0 px");
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  cv::Mat mask(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  // "Up" is the side of the table the right camera is on.
  const Eigen::Vector3d n = table.normal.normalized();
  const Eigen::Vector3d up = table.signed_distance(Eigen::Vector3d::Zero()) >= 0 ? n : Eigen::Vector3d(-n);
  const Eigen::Vector3d foot = column.foot - table.signed_distance(column.foot) / table.normal.norm() * n;
  const Eigen::Vector3d u = up.unitOrthogonal(), v = up.cross(u);
  // Rings of the surface (the outline of a cylinder's image is that of its end circles and the
  // lines between them; intermediate rings keep lens distortion's bending in).
  constexpr int kRings = 9, kPerRing = 48;
  std::vector<cv::Point> pixels;
  for (int ring = 0; ring < kRings; ++ring) {
    const Eigen::Vector3d centre = foot + column.height * ring / (kRings - 1) * up;
    for (int k = 0; k < kPerRing; ++k) {
      const double a = 2 * M_PI * k / kPerRing;
      Eigen::Vector3d p = centre + column.radius * (std::cos(a) * u + std::sin(a) * v);
      if (side == Side::Left) p = rig.R.transpose() * (p - rig.T);
      if (p.z() <= 1e-3) continue;  // behind this camera
      const Eigen::Vector2d px = camera.project(p);
      if (!px.allFinite()) continue;
      pixels.emplace_back(cvRound(px.x()), cvRound(px.y()));
    }
  }
  if (pixels.size() < 3) return mask;
  std::vector<cv::Point> hull;
  cv::convexHull(pixels, hull);
  cv::fillConvexPoly(mask, hull, cv::Scalar(255));
  if (margin_px > 0)
    cv::dilate(mask, mask, cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * margin_px + 1, 2 * margin_px + 1)));
  return mask;
}

cv::Mat outline_band(const cv::Mat& region, int band_px) {
  if (band_px < 1) throw std::invalid_argument("outline band must be >= 1 px");
  if (region.type() != CV_8UC1) throw std::invalid_argument("outline band: the region must be an 8-bit single-channel mask");
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * band_px + 1, 2 * band_px + 1));
  cv::Mat outer, inner;
  cv::dilate(region, outer, kernel);
  cv::erode(region, inner, kernel, cv::Point(-1, -1), 1, cv::BORDER_CONSTANT, cv::Scalar(0));
  return outer - inner;
}

cv::Mat columns_mask(const StereoRig& rig, Side side, const Plane& table, const std::vector<Column>& columns,
                     int margin_px, int band_px) {
  if (band_px < 0) throw std::invalid_argument("column band must be >= 0 px");
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  cv::Mat mask(camera.height, camera.width, CV_8UC1, cv::Scalar(0));
  for (const Column& column : columns) {
    // Each outline on its own: the band of a union would lose where two columns overlap.
    const cv::Mat region = column_mask(rig, side, table, column, band_px > 0 ? 0 : margin_px);
    mask |= band_px > 0 ? outline_band(region, band_px) : region;
  }
  return mask;
}

}  // namespace nudge::geometry
