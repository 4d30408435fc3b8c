#pragma once
// Stereo triangulation of symmetry lines (thesis sec. 4.3.3): each camera's symmetry line, projected
// out from the camera's focal point to depth zmax, is a triangle in 3D; the intersection of the left
// and right triangles (Moller 1997), both in the right camera's frame, is the object's symmetry axis.
#include <Eigen/Core>

#include <utility>

#include "nudge/geometry/outcome.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/symmetry/line.hpp"

namespace nudge::geometry {

struct Segment3 {
  Eigen::Vector3d a = Eigen::Vector3d::Zero(), b = Eigen::Vector3d::Zero();
  double length() const { return (b - a).norm(); }
  Eigen::Vector3d direction() const { return (b - a).normalized(); }  // unit, a -> b
};

struct Triangle {
  Eigen::Vector3d a, b, c;  // for a back-projected line: a = the focal point
};

struct TriangulationParams {
  double zmax = 2.0;  // m: depth of the projected triangle (thesis: 2.0 m, beyond arm's reach)
  // 0: the thesis' plane, through the two undistorted border endpoints (eq. 4.2-4.4).
  // >= 3: undistort this many samples along the line's support segment (Line::seg1..seg2, else the
  // border endpoints) and fit the plane through the focal point to them. Lens distortion bends the
  // image of a straight axis; the fitted straight line drifts from it fastest at the image border,
  // so two border points alone tilt the plane. The triangle's corners stay the border rays.
  int plane_samples = 32;
};

// Where the line (r, theta) meets the border of a w x h image (eq. 4.1-4.3). Fails if the line
// misses the image (or only touches a corner).
Outcome<std::pair<Eigen::Vector2d, Eigen::Vector2d>> line_endpoints(double r, double theta, int width, int height);

// The triangle (focal point, zmax-deep end points) of a symmetry line, in that camera's own frame.
Outcome<Triangle> backproject_line(const Camera& camera, const symmetry::Line& line,
                                   const TriangulationParams& params = {});

// Moller's triangle-triangle test, returning the segment the two triangles share. Fails for
// degenerate triangles, parallel or coplanar planes, and triangles that do not meet.
Outcome<Segment3> intersect_triangles(const Triangle& first, const Triangle& second);

// The 3D symmetry axis, in the right camera's frame, from one line in each image.
Outcome<Segment3> triangulate_axis(const StereoRig& rig, const symmetry::Line& left_line,
                                   const symmetry::Line& right_line, const TriangulationParams& params = {});

}  // namespace nudge::geometry
