#pragma once
// Which image lines can be the image of an object's axis (issue 14). An object stands upright on
// the table, so its axis is parallel to the table's normal, and the plane through the camera
// centre and the axis' image contains that normal (in the image: the line passes through the
// vertical vanishing point). Lines in the table's texture, and most lines between two objects,
// are far from it: on the busy-table development family the true axes' images are within 2 deg,
// while half of the other accumulator peaks are more than 8 deg off (docs/clutter.md).
#include <Eigen/Core>

#include <vector>

#include "nudge/geometry/outcome.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/stereo_pairing.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/symmetry/line.hpp"

namespace nudge::geometry {

// The angle (deg, 0-90) between the table's normal and the plane through `side`'s camera centre
// and the line (near its support segment, lens distortion removed): 0 for the image of an upright
// axis; an axis in that plane is tilted from the normal by at least this much. `table` is in the
// right camera's frame, as everywhere in the rig. Fails where the lens model cannot be inverted.
Outcome<double> upright_tilt_deg(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line);

// The line turned about its support segment's middle until it is the image of an upright axis
// (the nearest such line there; the support segment is kept, moved onto it): two views of an
// object then triangulate to an exactly upright axis, and the line's angle no longer carries the
// accumulator's 1-degree bins. Fails where the lens model cannot be inverted.
Outcome<symmetry::Line> snapped_upright(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line);

// The lines (in their order) whose tilt is at most `max_tilt_deg`, with `snap` snapped upright;
// lines whose tilt cannot be computed are dropped. Throws std::invalid_argument unless
// 0 <= max_tilt_deg <= 90.
std::vector<symmetry::Line> upright_lines(const StereoRig& rig, Side side, const Plane& table,
                                          const std::vector<symmetry::Line>& lines, double max_tilt_deg,
                                          bool snap = false);

// Where the line's support segment stands on the table: of its two ends' rays, the table point
// nearer the camera (the segment's lower end; the only one, when the other ray misses the table in
// front of the camera). For an object's line that is its foot, or a little beyond it when its
// lowest edges are above the table; for a wall's, the table behind the wall's foot or nothing.
// Right camera frame. Fails where neither end's ray meets the table in front of the camera, or the
// lens model cannot be inverted.
Outcome<Eigen::Vector3d> support_foot(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line);

// The lines (in their order) whose support foot lies within `radius` of `centre` along the table
// (right camera frame), and not nearer than `inner_radius`: a line standing on the wall, beyond the
// table's far edge or far out on the table cannot be an object the arm reaches, nor can the arm's
// own base column standing at `centre`, and either would take the place of an object among the
// lines the detector keeps. Lines without a foot are dropped. Throws std::invalid_argument unless
// 0 <= inner_radius < radius.
std::vector<symmetry::Line> lines_standing_within(const StereoRig& rig, Side side, const Plane& table,
                                                  const Eigen::Vector3d& centre, double radius,
                                                  const std::vector<symmetry::Line>& lines, double inner_radius = 0.0);

}  // namespace nudge::geometry
