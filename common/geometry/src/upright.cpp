#include "nudge/geometry/upright.hpp"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

namespace nudge::geometry {

namespace {

// Two points on the line either side of its support segment's middle: short enough that lens
// distortion bends the line little between them, long enough to fix its direction.
constexpr double kHalfSpanPx = 40;

}  // namespace

Outcome<double> upright_tilt_deg(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line) {
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  // The table's normal in this camera's frame (rig.R takes left-camera directions to the right's).
  const Eigen::Vector3d up = side == Side::Left ? Eigen::Vector3d(rig.R.transpose() * table.normal) : table.normal;
  const Eigen::Vector2d direction(-std::sin(line.theta), std::cos(line.theta));
  // The support segment's middle, moved onto the line (it is, up to rounding).
  const Eigen::Vector2d centre(0.5 * (camera.width - 1), 0.5 * (camera.height - 1));
  const Eigen::Vector2d normal(std::cos(line.theta), std::sin(line.theta));
  Eigen::Vector2d middle(0.5 * (line.seg1.x + line.seg2.x), 0.5 * (line.seg1.y + line.seg2.y));
  middle += (line.r - (middle - centre).dot(normal)) * normal;
  Eigen::Vector3d rays[2];
  for (int i = 0; i < 2; ++i) {
    const auto n = camera.normalise(middle + (i == 0 ? -kHalfSpanPx : kHalfSpanPx) * direction);
    if (!n) return Outcome<double>::failure("upright check: " + n.reason());
    rays[i] = Eigen::Vector3d(n->x(), n->y(), 1.0);
  }
  const Eigen::Vector3d plane_normal = rays[0].cross(rays[1]);
  if (plane_normal.norm() <= 0) return Outcome<double>::failure("upright check: the line's points coincide");
  const double s = std::fabs(plane_normal.normalized().dot(up.normalized()));
  return Outcome<double>::success(std::asin(std::min(1.0, s)) * 180 / M_PI);
}

Outcome<symmetry::Line> snapped_upright(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line) {
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  const Eigen::Vector3d up =
      (side == Side::Left ? Eigen::Vector3d(rig.R.transpose() * table.normal) : table.normal).normalized();
  const Eigen::Vector2d middle(0.5 * (line.seg1.x + line.seg2.x), 0.5 * (line.seg1.y + line.seg2.y));
  const auto n = camera.normalise(middle);
  if (!n) return Outcome<symmetry::Line>::failure("upright snap: " + n.reason());
  // An upright segment through the middle's ray at unit depth, projected back into the image.
  const Eigen::Vector3d at(n->x(), n->y(), 1.0);
  const double half = kHalfSpanPx / camera.K(0, 0);  // about kHalfSpanPx in the image
  const Eigen::Vector3d low = at - half * up, high = at + half * up;
  if (low.z() <= 0 || high.z() <= 0) return Outcome<symmetry::Line>::failure("upright snap: the vertical leaves the view");
  const Eigen::Vector2d a = camera.project(low), b = camera.project(high);
  const Eigen::Vector2d d = b - a;
  if (d.norm() <= 0) return Outcome<symmetry::Line>::failure("upright snap: the vertical projects to a point");
  double theta = std::atan2(d.x(), -d.y());  // the normal (cos, sin) is perpendicular to d
  while (theta > M_PI / 2) theta -= M_PI;
  while (theta <= -M_PI / 2) theta += M_PI;
  const Eigen::Vector2d centre(0.5 * (camera.width - 1), 0.5 * (camera.height - 1));
  const Eigen::Vector2d normal(std::cos(theta), std::sin(theta));
  symmetry::Line out = line;
  out.theta = theta;
  out.r = (middle - centre).dot(normal);
  symmetry::border_endpoints(out.r, out.theta, camera.width, camera.height, &out.end1, &out.end2);
  for (cv::Point2d* end : {&out.seg1, &out.seg2}) {  // onto the new line
    const double off = (Eigen::Vector2d(end->x, end->y) - centre).dot(normal) - out.r;
    *end -= cv::Point2d(off * normal.x(), off * normal.y());
  }
  return Outcome<symmetry::Line>::success(out);
}

std::vector<symmetry::Line> upright_lines(const StereoRig& rig, Side side, const Plane& table,
                                          const std::vector<symmetry::Line>& lines, double max_tilt_deg, bool snap) {
  if (!(max_tilt_deg >= 0 && max_tilt_deg <= 90)) throw std::invalid_argument("upright check: max_tilt_deg must be in [0, 90]");
  std::vector<symmetry::Line> out;
  for (const symmetry::Line& line : lines) {
    const auto tilt = upright_tilt_deg(rig, side, table, line);
    if (!tilt || *tilt > max_tilt_deg) continue;
    if (!snap) {
      out.push_back(line);
      continue;
    }
    const auto snapped = snapped_upright(rig, side, table, line);
    if (snapped) out.push_back(*snapped);
  }
  return out;
}

Outcome<Eigen::Vector3d> support_foot(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line) {
  const Camera& camera = side == Side::Left ? rig.left : rig.right;
  const Eigen::Vector3d origin = side == Side::Left ? rig.left_centre() : Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> foot;
  for (const cv::Point2d& end : {line.seg1, line.seg2}) {
    const auto n = camera.normalise(Eigen::Vector2d(end.x, end.y));
    if (!n) return Outcome<Eigen::Vector3d>::failure("support foot: " + n.reason());
    Eigen::Vector3d ray(n->x(), n->y(), 1.0);
    if (side == Side::Left) ray = rig.R * ray;  // into the right camera's frame
    const auto hit = ray_meets_plane(origin, ray, table);
    if (hit && (!foot || (*hit - origin).norm() < (*foot - origin).norm())) foot = hit;
  }
  if (!foot) return Outcome<Eigen::Vector3d>::failure("support foot: the line's support does not reach the table");
  return Outcome<Eigen::Vector3d>::success(*foot);
}

std::vector<symmetry::Line> lines_standing_within(const StereoRig& rig, Side side, const Plane& table,
                                                  const Eigen::Vector3d& centre, double radius,
                                                  const std::vector<symmetry::Line>& lines, double inner_radius) {
  if (!(radius > 0)) throw std::invalid_argument("lines standing within: the radius must be > 0");
  if (!(inner_radius >= 0 && inner_radius < radius))
    throw std::invalid_argument("lines standing within: the inner radius must be >= 0 and below the radius");
  const Eigen::Vector3d n = table.normal.normalized();
  std::vector<symmetry::Line> kept;
  for (const symmetry::Line& line : lines) {
    const auto foot = support_foot(rig, side, table, line);
    if (!foot) continue;
    Eigen::Vector3d offset = *foot - centre;
    offset -= offset.dot(n) * n;  // along the table
    if (offset.norm() <= radius && offset.norm() >= inner_radius) kept.push_back(line);
  }
  return kept;
}

}  // namespace nudge::geometry
