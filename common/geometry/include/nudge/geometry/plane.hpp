#pragma once
// The table plane and what an axis does with it (thesis sec. 4.3.5 and 6.2.1): least-squares plane
// through triangulated points, axis-table intersection, and the filters that reject axes which
// cannot belong to an object standing on the table.
#include <Eigen/Core>

#include <optional>
#include <vector>

#include "nudge/geometry/outcome.hpp"
#include "nudge/geometry/triangulation.hpp"
#include "nudge/robot/workspace.hpp"

namespace nudge::geometry {

// normal . p + offset = 0, |normal| = 1, oriented so the frame's origin (the camera) lies on the
// positive side: for a table seen from above the normal points up.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double offset = 0;
  double rms_residual = 0;  // of the fit, m
  double signed_distance(const Eigen::Vector3d& p) const { return normal.dot(p) + offset; }
};

// Total least squares. Fails for fewer than 3 points, non-finite points or (nearly) collinear ones.
Outcome<Plane> fit_plane(const std::vector<Eigen::Vector3d>& points);

// Where the infinite line through the axis meets the plane. Fails if they are (nearly) parallel.
Outcome<Eigen::Vector3d> intersect_axis_plane(const Segment3& axis, const Plane& plane);

// Where the ray from `origin` along `direction` meets the plane, ahead of the origin; nothing when
// it runs parallel to the plane or meets it behind the origin (a camera ray that misses the table).
std::optional<Eigen::Vector3d> ray_meets_plane(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction,
                                               const Plane& plane);

// Angle between the axis and the plane's normal, degrees in [0, 90].
double tilt_from_normal_deg(const Segment3& axis, const Plane& plane);

// 2D coordinates on a plane: origin = the foot of the camera centre, x along the camera's x axis
// projected onto the plane, y = normal x x. Used to cluster table intersects in 2D.
struct PlaneFrame {
  Eigen::Vector3d origin, x_axis, y_axis;
  explicit PlaneFrame(const Plane& plane);
  Eigen::Vector2d to_plane(const Eigen::Vector3d& p) const;
  Eigen::Vector3d to_space(const Eigen::Vector2d& q) const;
};

struct AxisFilter {
  double max_tilt_deg = 15;   // from the table normal (thesis: 15 deg in ch. 4, 10 deg in ch. 6)
  double max_range_m = 1.2;   // table intersection farther from the (right) camera: out of reach
  // Optional workspace ring on the table (ch. 6: 150-350 mm around the arm base): the arm's
  // (robot::Workspace) unless set.
  std::optional<Eigen::Vector3d> ring_centre;
  double ring_inner_m = robot::Workspace{}.ring_inner, ring_outer_m = robot::Workspace{}.ring_outer;
};

struct TableHit {
  Eigen::Vector3d point;  // axis-table intersection, camera frame
  double tilt_deg = 0;    // axis angle from the table normal
  double range_m = 0;     // distance of `point` from the camera centre
};

// Intersects the axis with the table and applies the filters; the reason names the failed test.
Outcome<TableHit> check_axis(const Segment3& axis, const Plane& table, const AxisFilter& filter = {});

}  // namespace nudge::geometry
