#include "nudge/geometry/plane.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <sstream>

namespace nudge::geometry {

namespace {
std::string fixed(double value, int digits) {
  std::ostringstream s;
  s.setf(std::ios::fixed);
  s.precision(digits);
  s << value;
  return s.str();
}
}  // namespace

Outcome<Plane> fit_plane(const std::vector<Eigen::Vector3d>& points) {
  using Result = Outcome<Plane>;
  if (points.size() < 3) return Result::failure("plane fit needs at least 3 points, got " + std::to_string(points.size()));
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  for (const auto& p : points) {
    if (!p.allFinite()) return Result::failure("plane fit: non-finite point");
    centroid += p;
  }
  centroid /= static_cast<double>(points.size());
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& p : points) scatter += (p - centroid) * (p - centroid).transpose();
  scatter /= static_cast<double>(points.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  const Eigen::Vector3d spread = solver.eigenvalues();  // ascending
  // The plane is defined only if the points span two directions.
  if (!(spread(1) > 1e-12 * std::max(spread(2), 1e-300)) || spread(2) < 1e-24)
    return Result::failure("plane fit: points are (nearly) collinear or coincident");
  Plane plane;
  plane.normal = solver.eigenvectors().col(0).normalized();
  plane.offset = -plane.normal.dot(centroid);
  if (plane.offset < 0) {  // orient towards the camera at the origin
    plane.normal = -plane.normal;
    plane.offset = -plane.offset;
  }
  plane.rms_residual = std::sqrt(std::max(0.0, spread(0)));
  return Result::success(plane);
}

Outcome<Eigen::Vector3d> intersect_axis_plane(const Segment3& axis, const Plane& plane) {
  using Result = Outcome<Eigen::Vector3d>;
  if (!axis.a.allFinite() || !axis.b.allFinite() || axis.length() < 1e-12)
    return Result::failure("axis is degenerate (zero length or non-finite)");
  const Eigen::Vector3d dir = axis.direction();
  const double along_normal = plane.normal.dot(dir);
  if (std::fabs(along_normal) < 1e-9) return Result::failure("axis is parallel to the plane");
  const double t = -plane.signed_distance(axis.a) / along_normal;
  return Result::success(axis.a + t * dir);
}

std::optional<Eigen::Vector3d> ray_meets_plane(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                               const Plane& plane) {
  const double along = plane.normal.dot(direction);
  if (std::abs(along) < 1e-12) return std::nullopt;
  const double t = -plane.signed_distance(origin) / along;
  if (!(t > 0) || !std::isfinite(t)) return std::nullopt;
  return origin + t * direction;
}

double tilt_from_normal_deg(const Segment3& axis, const Plane& plane) {
  if (axis.length() < 1e-12) return 90.0;
  const double c = std::min(1.0, std::fabs(plane.normal.dot(axis.direction())));
  return std::acos(c) * 180.0 / M_PI;
}

PlaneFrame::PlaneFrame(const Plane& plane) : origin(-plane.offset * plane.normal) {
  // The camera's x axis projected onto the plane; its y axis if x is (nearly) the normal.
  Eigen::Vector3d x = Eigen::Vector3d::UnitX() - plane.normal.x() * plane.normal;
  if (x.norm() < 1e-6) x = Eigen::Vector3d::UnitY() - plane.normal.y() * plane.normal;
  x_axis = x.normalized();
  y_axis = plane.normal.cross(x_axis);
}

Eigen::Vector2d PlaneFrame::to_plane(const Eigen::Vector3d& p) const {
  return {x_axis.dot(p - origin), y_axis.dot(p - origin)};
}

Eigen::Vector3d PlaneFrame::to_space(const Eigen::Vector2d& q) const { return origin + q.x() * x_axis + q.y() * y_axis; }

Outcome<TableHit> check_axis(const Segment3& axis, const Plane& table, const AxisFilter& filter) {
  using Result = Outcome<TableHit>;
  const auto point = intersect_axis_plane(axis, table);
  if (!point) return Result::failure(point.reason());
  TableHit hit;
  hit.point = *point;
  hit.tilt_deg = tilt_from_normal_deg(axis, table);
  hit.range_m = hit.point.norm();
  if (hit.tilt_deg > filter.max_tilt_deg)
    return Result::failure("axis tilted " + fixed(hit.tilt_deg, 1) + " deg from the table normal (max " +
                           fixed(filter.max_tilt_deg, 1) + ")");
  if (hit.range_m > filter.max_range_m)
    return Result::failure("table intersection " + fixed(hit.range_m, 3) + " m from the camera (max " +
                           fixed(filter.max_range_m, 3) + ")");
  if (filter.ring_centre) {
    const double radius = (hit.point - *filter.ring_centre).norm();
    if (radius < filter.ring_inner_m || radius > filter.ring_outer_m)
      return Result::failure("table intersection " + fixed(radius * 1000, 0) + " mm from the arm base, outside the " +
                             fixed(filter.ring_inner_m * 1000, 0) + "-" + fixed(filter.ring_outer_m * 1000, 0) +
                             " mm workspace ring");
  }
  return Result::success(hit);
}

}  // namespace nudge::geometry
