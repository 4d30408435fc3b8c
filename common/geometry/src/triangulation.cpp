#include "nudge/geometry/triangulation.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace nudge::geometry {

namespace {

Eigen::Vector2d to_eigen(const cv::Point2d& p) { return {p.x, p.y}; }

std::string describe(double r, double theta) {
  std::ostringstream s;
  s << "(R " << r << " px, theta " << theta * 180.0 / M_PI << " deg)";
  return s.str();
}

// Unit ray through an undistorted normalised point.
Eigen::Vector3d ray(const Eigen::Vector2d& normalised) { return Eigen::Vector3d(normalised.x(), normalised.y(), 1).normalized(); }

// Normal of the plane through the origin that best fits the rays (smallest eigenvector of sum r r^T).
Eigen::Vector3d plane_normal_through_origin(const std::vector<Eigen::Vector3d>& rays) {
  Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
  for (const auto& r : rays) scatter += r * r.transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver(scatter);
  return solver.eigenvectors().col(0);
}

// The undistorted rays of samples along the line's support segment (or its border chord).
std::vector<Eigen::Vector3d> sample_rays(const Camera& camera, const symmetry::Line& line,
                                         const Eigen::Vector2d& end1, const Eigen::Vector2d& end2, int samples) {
  Eigen::Vector2d from = end1, to = end2;
  const Eigen::Vector2d seg1 = to_eigen(line.seg1), seg2 = to_eigen(line.seg2);
  const auto inside = [&](const Eigen::Vector2d& p) {
    return p.allFinite() && p.x() >= 0 && p.y() >= 0 && p.x() <= camera.width - 1 && p.y() <= camera.height - 1;
  };
  if ((seg2 - seg1).norm() >= 2.0 && inside(seg1) && inside(seg2)) {
    from = seg1;
    to = seg2;
  }
  std::vector<Eigen::Vector3d> rays;
  for (int i = 0; i < samples; ++i) {
    const double t = static_cast<double>(i) / (samples - 1);
    const auto normalised = camera.normalise(from + t * (to - from));
    if (normalised) rays.push_back(ray(*normalised));
  }
  return rays;
}

// The points where a triangle crosses a plane, given its vertices' signed distances to it.
std::vector<Eigen::Vector3d> crossing_points(const Triangle& t, const double (&distance)[3], double eps) {
  const Eigen::Vector3d v[3] = {t.a, t.b, t.c};
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    if (std::fabs(distance[i]) <= eps) points.push_back(v[i]);
    if ((distance[i] > eps && distance[j] < -eps) || (distance[i] < -eps && distance[j] > eps))
      points.push_back(v[i] + (v[j] - v[i]) * (distance[i] / (distance[i] - distance[j])));
  }
  return points;
}

bool all_one_side(const double (&d)[3], double eps) {
  return (d[0] > eps && d[1] > eps && d[2] > eps) || (d[0] < -eps && d[1] < -eps && d[2] < -eps);
}

}  // namespace

Outcome<std::pair<Eigen::Vector2d, Eigen::Vector2d>> line_endpoints(double r, double theta, int width, int height) {
  using Result = Outcome<std::pair<Eigen::Vector2d, Eigen::Vector2d>>;
  if (!std::isfinite(r) || !std::isfinite(theta)) return Result::failure("symmetry line has non-finite (R, theta)");
  if (width <= 0 || height <= 0) return Result::failure("image size must be positive");
  cv::Point2d p1, p2;
  symmetry::border_endpoints(r, theta, width, height, &p1, &p2);
  if (cv::norm(p2 - p1) < 1.0) {
    return Result::failure("symmetry line " + describe(r, theta) + " misses the " + std::to_string(width) + "x" +
                           std::to_string(height) + " image");
  }
  return Result::success({to_eigen(p1), to_eigen(p2)});
}

Outcome<Triangle> backproject_line(const Camera& camera, const symmetry::Line& line, const TriangulationParams& params) {
  using Result = Outcome<Triangle>;
  if (!(params.zmax > 0) || !std::isfinite(params.zmax)) return Result::failure("zmax must be a positive number");
  const auto ends = line_endpoints(line.r, line.theta, camera.width, camera.height);
  if (!ends) return Result::failure(ends.reason());
  const auto n1 = camera.normalise(ends->first), n2 = camera.normalise(ends->second);
  if (!n1) return Result::failure("first end point: " + n1.reason());
  if (!n2) return Result::failure("second end point: " + n2.reason());
  Eigen::Vector3d r1 = ray(*n1), r2 = ray(*n2);

  if (params.plane_samples >= 3) {
    const std::vector<Eigen::Vector3d> rays = sample_rays(camera, line, ends->first, ends->second, params.plane_samples);
    if (rays.size() < 3) return Result::failure("too few undistortable samples along the symmetry line");
    const Eigen::Vector3d normal = plane_normal_through_origin(rays);
    r1 -= r1.dot(normal) * normal;  // keep the border rays, moved into the fitted plane
    r2 -= r2.dot(normal) * normal;
  } else if (params.plane_samples != 0) {
    return Result::failure("plane_samples must be 0 (thesis end points) or >= 3");
  }
  // eq. 4.4: pp = zmax [pnorm; 1].
  if (!(r1.z() > 1e-9) || !(r2.z() > 1e-9)) return Result::failure("symmetry line end point ray points away from the scene");
  Triangle t{Eigen::Vector3d::Zero(), params.zmax * r1 / r1.z(), params.zmax * r2 / r2.z()};
  if (t.b.cross(t.c).norm() < 1e-12 * params.zmax * params.zmax)
    return Result::failure("symmetry line end points project onto one ray");
  return Result::success(t);
}

Outcome<Segment3> intersect_triangles(const Triangle& first, const Triangle& second) {
  using Result = Outcome<Segment3>;
  Eigen::Vector3d n1 = (first.b - first.a).cross(first.c - first.a);
  Eigen::Vector3d n2 = (second.b - second.a).cross(second.c - second.a);
  if (!n1.allFinite() || !n2.allFinite()) return Result::failure("triangle has non-finite vertices");
  const double scale = std::max({first.a.norm(), first.b.norm(), first.c.norm(), second.a.norm(), second.b.norm(),
                                 second.c.norm(), 1e-300});
  if (n1.norm() < 1e-12 * scale * scale || n2.norm() < 1e-12 * scale * scale)
    return Result::failure("degenerate triangle (collinear vertices)");
  n1.normalize();
  n2.normalize();
  const Eigen::Vector3d direction = n1.cross(n2);
  if (direction.norm() < 1e-9) return Result::failure("back-projection planes are parallel (or coplanar)");

  // Signed distances of each triangle's vertices to the other's plane (Moller's rejection tests).
  const double eps = 1e-12 * scale;
  const double d1[3] = {n2.dot(first.a - second.a), n2.dot(first.b - second.a), n2.dot(first.c - second.a)};
  const double d2[3] = {n1.dot(second.a - first.a), n1.dot(second.b - first.a), n1.dot(second.c - first.a)};
  if (all_one_side(d1, eps) || all_one_side(d2, eps))
    return Result::failure("triangles do not intersect (one lies on one side of the other's plane)");

  // Both crossing segments lie on the planes' common line: overlap their intervals along it.
  const std::vector<Eigen::Vector3d> on1 = crossing_points(first, d1, eps), on2 = crossing_points(second, d2, eps);
  if (on1.empty() || on2.empty()) return Result::failure("triangles do not intersect");
  const auto along = [&](const Eigen::Vector3d& p) { return direction.dot(p); };
  const auto by_along = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) { return along(p) < along(q); };
  const auto [lo1, hi1] = std::minmax_element(on1.begin(), on1.end(), by_along);
  const auto [lo2, hi2] = std::minmax_element(on2.begin(), on2.end(), by_along);
  const Eigen::Vector3d start = along(*lo1) > along(*lo2) ? *lo1 : *lo2;
  const Eigen::Vector3d end = along(*hi1) < along(*hi2) ? *hi1 : *hi2;
  if (along(end) - along(start) <= 1e-12 * scale) return Result::failure("triangles do not overlap along their common line");
  return Result::success(Segment3{start, end});
}

Outcome<Segment3> triangulate_axis(const StereoRig& rig, const symmetry::Line& left_line,
                                   const symmetry::Line& right_line, const TriangulationParams& params) {
  using Result = Outcome<Segment3>;
  if (!rig.T.allFinite() || !rig.R.allFinite()) return Result::failure("stereo extrinsics are not finite");
  if (rig.T.norm() < 1e-9) return Result::failure("camera centres coincide (T = 0): no baseline to triangulate");
  const auto left = backproject_line(rig.left, left_line, params);
  if (!left) return Result::failure("left line: " + left.reason());
  const auto right = backproject_line(rig.right, right_line, params);
  if (!right) return Result::failure("right line: " + right.reason());
  // eq. 4.5: bring the left triangle into the right camera's frame.
  const Triangle moved{rig.left_to_right(left->a), rig.left_to_right(left->b), rig.left_to_right(left->c)};
  const auto axis = intersect_triangles(moved, *right);
  if (!axis) return Result::failure(axis.reason());
  return axis;
}

}  // namespace nudge::geometry
