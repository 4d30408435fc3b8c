#pragma once
// From stereo symmetry lines to object locations on the table (thesis sec. 4.3.4 and 6.2):
// every left x right pairing of lines is triangulated; axes that stand upright on the table are
// kept; over many stereo frames their table intersections are QT-clustered, and the cluster
// centroids are the "interesting locations" the robot may nudge.
#include <Eigen/Core>

#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "nudge/geometry/axis_appearance.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/qt_cluster.hpp"
#include "nudge/geometry/stereo_pairing.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/triangulation.hpp"
#include "nudge/robot/workspace.hpp"

namespace nudge::geometry {

// The heights above the table (along the axis, from its table hit) that a line's support segment
// (Line::seg1..seg2) covers: where the camera rays through its ends pass closest to the axis.
struct HeightRange {
  double low = 0, high = 0;
};

// One left x right pairing that gave a valid axis.
struct PairedAxis {
  int left_index = 0, right_index = 0;  // into the lines passed in
  Segment3 axis;                        // right camera frame
  std::optional<TableHit> hit;          // set when a table plane was given
  // The left and the right line's support_heights on the axis, once computed (with_support_heights):
  // the stereo appearance and the stereo check both read them.
  std::optional<std::pair<HeightRange, HeightRange>> support;
};

struct PairingResult {
  int pairings = 0;                     // pairings tried
  std::vector<PairedAxis> axes;         // the valid ones, in pairing order (left-major)
  std::vector<std::string> rejections;  // "left 1 x right 2: <reason>" for every other pairing
};

// Triangulates each of the first `max_lines` left lines (all when <= 0) with each of the first
// `max_lines` right lines. With a table, an axis is valid only if it passes `filter`; without one,
// if it triangulates. Lines with non-finite numbers are rejected with a reason, never a NaN axis.
PairingResult triangulate_pairings(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                   const std::vector<symmetry::Line>& right, const Plane* table,
                                   const AxisFilter& filter = {}, const TriangulationParams& params = {},
                                   int max_lines = 0);

bool is_finite(const symmetry::Line& line);  // r, theta and the stored end points

// A frame on the table for everything downstream of triangulation (arm, planner): z along the
// table normal (up, towards the cameras), origin where `origin_hint` (the arm base, in the right
// camera's frame) meets the table along the normal, else below the right camera; x the right
// camera's x axis projected onto the table, y = z x x.
class TableFrame {
 public:
  explicit TableFrame(const Plane& table, const std::optional<Eigen::Vector3d>& origin_hint = std::nullopt);
  Eigen::Vector3d to_table(const Eigen::Vector3d& camera_point) const;
  Eigen::Vector3d to_camera(const Eigen::Vector3d& table_point) const;
  const Eigen::Vector3d& origin() const { return origin_; }  // right camera frame

 private:
  Eigen::Vector3d origin_;
  Eigen::Matrix3d axes_;  // rows: x, y, z of the table frame in the right camera's frame
};

struct LocationParams {
  int frames = 25;           // stereo pairs gathered per request (thesis: 25)
  int lines_per_image = 3;   // top lines per image: 9 pairings per stereo pair (thesis: 3)
  double max_tilt_deg = 10;  // from the table normal (thesis ch. 6: 10 deg)
  double max_range_m = 1.2;  // from the right camera
  // The arm's workspace ring (thesis: 150-350 mm), robot::Workspace's unless a service sets it.
  double ring_inner_m = robot::Workspace{}.ring_inner, ring_outer_m = robot::Workspace{}.ring_outer;
  QtParams qt;               // radius 10 mm, clusters of at least 1/9 of all intersects
  // Stereo consistency (issue 14), off by default (the thesis pairs every line with every line):
  // a left and a right line are one object's only if the heights their support segments cover
  // on the triangulated axis agree (overlap / union >= min_height_overlap) and start on the table
  // (the lower end within max_foot_height_m of it); each line then pairs at most once per frame,
  // the most consistent pairing first. Values chosen on the busy-table family (docs/clutter.md).
  bool stereo_check = false;
  double min_height_overlap = 0.3;
  double max_foot_height_m = 0.08;
  // Stereo appearance (issue 14), off at 0: with the frame's images given to add_frame, a pairing
  // counts only if the two cameras show the same colour at no less than this share of the heights
  // along its axis (axis_colour_agreement, up to the lower of the two support segments' tops,
  // clamped to [appearance_min_top_m, appearance_max_top_m]). Checked before the stereo check
  // pairs each line once, so a phantom does not take an object's line.
  double min_axis_colour_agreement = 0;
  double appearance_min_top_m = 0.04, appearance_max_top_m = 0.30;
  // Two support segments covering the same heights (overlap / union at least this) already say
  // "one object": such a pairing needs no appearance check. A finely patterned object looks
  // different to the two cameras (they see its surface ~1 cm apart) but its outline does not.
  double appearance_waived_at_overlap = 0.7;
  AxisAppearanceParams appearance;
  // Beyond the thesis (one object per scene): objects already explored that still stand on the
  // table (right camera frame, on it). Their lines are the strongest in every later survey and
  // would crowd out the objects still to find, so a line that is the image of an upright axis at
  // one of them (is_image_of_upright_axis, within explored_line_px) is not among the
  // lines_per_image taken. An unexplored object standing in line with one in a camera loses its
  // line in that camera too. The tolerance is wide (16 px, about 1.5 cm at the objects'
  // distance): the place explored is known to a centimetre or two (where the object was put
  // back, or came to rest), and a mug's strongest line lies off its body's axis by its handle
  // (the demo's mug: 9 px). Chosen on recorded development runs (8, 12, 16, 24 px:
  // docs/results/explored_px_dev.md): 16 px left 17 % fewer phantom candidates and no object
  // fewer a candidate; the held-out runs replayed afterwards agreed (explored_px_heldout.md).
  std::vector<Eigen::Vector3d> explored;
  double explored_line_px = 16;
  // Beyond the thesis: when > 0, a line whose plane leans more than this from the table's normal
  // (upright_tilt_deg: it cannot be the image of an upright axis) is not among the lines taken.
  // Objects' lines lean 0-1 deg, lines between two objects 2.5-5 deg, the clutter's often more
  // (docs/supervisor.md). 0: off (the thesis takes the strongest lines whatever they are).
  double max_line_tilt_deg = 0;
  // Beyond the thesis: the arm's own base column (an upright cylinder at the arm_base the finder
  // is given, always in view) is symmetric, and its line is often an image's strongest, taking
  // one of the lines_per_image places in every frame of every survey (the demo scene: in both
  // cameras, so the fourth-ranked bottle never paired). A line within column_line_px of the image
  // of the column's axis (is_image_of_upright_axis) is
  //   Counted:   a line like any other (the thesis);
  //   Dropped:   left out, like an explored object's. An object standing in line with the column
  //              in a camera loses its line there: single objects placed in front of the arm
  //              often do (replayed held-out runs lost 6 of 24);
  //   Uncounted: paired, but not one of the lines_per_image: the next line is paired too, and an
  //              object in line with the column, whose line is the column's, still pairs.
  enum class ColumnLines { Counted, Dropped, Uncounted };
  ColumnLines column_lines = ColumnLines::Counted;
  double column_line_px = 8;
};

// "counted", "dropped", "uncounted" (std::invalid_argument naming the text otherwise).
LocationParams::ColumnLines parse_column_lines(const std::string& text);

// Whether `line` (in the camera of `side`) is the image of an upright axis standing at `foot`
// (right camera frame, on `table`): the foot and the point 0.1 m above it both project within
// `tolerance_px` of the line. False for a foot behind the camera.
bool is_image_of_upright_axis(const StereoRig& rig, Side side, const Plane& table, const symmetry::Line& line,
                              const Eigen::Vector3d& foot, double tolerance_px);

// The strongest lines (`lines` strongest first) up to `count` of them, where a line that is the
// image of the arm's base column (is_image_of_upright_axis at `column_foot`, within
// `column_px`) rides along without counting: the column is always in view and often an image's
// strongest line, and would otherwise take the place of an object's line wherever lines are
// capped (the survey's lines per image, the symmetry service's lines published within reach).
std::vector<symmetry::Line> first_lines_column_uncounted(const StereoRig& rig, Side side, const Plane& table,
                                                         const std::vector<symmetry::Line>& lines, int count,
                                                         const Eigen::Vector3d& column_foot, double column_px);

// Throws std::invalid_argument naming the offending parameter.
void validate(const LocationParams& params);

Outcome<HeightRange> support_heights(const StereoRig& rig, Side side, const symmetry::Line& line,
                                     const Segment3& axis, const TableHit& hit, const Plane& table);
// Overlap / union of two height ranges, in [0, 1] (0 when they do not overlap).
double height_overlap(const HeightRange& a, const HeightRange& b);
// `result` with every pairing's PairedAxis::support set where both lines' support heights are found.
PairingResult with_support_heights(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                   const std::vector<symmetry::Line>& right, PairingResult result, const Plane& table);

// The pairings of `result` whose two images agree along the axis (min_axis_colour_agreement of
// `params`); all of them when it is 0.
PairingResult appearance_consistent(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                    const std::vector<symmetry::Line>& right, const PairingResult& result,
                                    const Plane& table, const cv::Mat& left_image, const cv::Mat& right_image,
                                    const LocationParams& params);

// The pairings of `result` (triangulate_pairings with a table) that pass the stereo check of
// `params`, each line used once, most consistent first.
std::vector<PairedAxis> consistent_pairings(const StereoRig& rig, const std::vector<symmetry::Line>& left,
                                            const std::vector<symmetry::Line>& right, const PairingResult& result,
                                            const Plane& table, const LocationParams& params);

struct Location {
  Eigen::Vector3d position;  // cluster centroid on the table, right camera frame
  int support = 0;           // intersects in the cluster
};

// Gathers table intersects over `frames` stereo pairs, then clusters them. Without an arm base the
// workspace ring cannot be applied and every upright axis on the table counts.
class LocationFinder {
 public:
  LocationFinder(const StereoRig& rig, const Plane& table, const std::optional<Eigen::Vector3d>& arm_base,
                 LocationParams params = {}, TriangulationParams triangulation = {});

  // The pairings one stereo pair's lines (strongest first) give, as add_frame counts them: the
  // indices are into the lines left after survey_lines and paired_lines (the lines given, when
  // nothing is explored, max_line_tilt_deg is 0 and the column's lines are counted).
  // With images (the ones the lines were found in), min_axis_colour_agreement applies.
  std::vector<PairedAxis> frame_axes(const std::vector<symmetry::Line>& left, const std::vector<symmetry::Line>& right,
                                     const cv::Mat& left_image = {}, const cv::Mat& right_image = {}) const;
  // Adds one stereo pair's lines (strongest first); returns how many intersects it contributed.
  // With min_axis_colour_agreement > 0 the images are needed (std::invalid_argument without them).
  int add_frame(const std::vector<symmetry::Line>& left, const std::vector<symmetry::Line>& right,
                const cv::Mat& left_image = {}, const cv::Mat& right_image = {});
  bool complete() const { return frames_ >= params_.frames; }
  int frames() const { return frames_; }
  int intersects() const { return static_cast<int>(points_.size()); }
  // The table intersects gathered so far (right camera frame), in the order they were added.
  const std::vector<Eigen::Vector3d>& intersect_points() const { return points_; }
  const AxisFilter& axis_filter() const { return filter_; }
  // QT clusters of the intersects gathered so far, largest first.
  std::vector<Location> locations() const;
  void reset();

 private:
  // The lines (in their order) that may be a new object's: not the image of an explored place's
  // axis, and (with max_line_tilt_deg) the image of an upright axis.
  std::vector<symmetry::Line> survey_lines(Side side, const std::vector<symmetry::Line>& lines) const;
  // Of those, the ones paired: the first lines_per_image, and the arm's base column's lines as
  // column_lines says.
  std::vector<symmetry::Line> paired_lines(Side side, const std::vector<symmetry::Line>& lines) const;

  StereoRig rig_;
  Plane table_;
  LocationParams params_;
  TriangulationParams triangulation_;
  AxisFilter filter_;
  PlaneFrame plane_frame_;
  int frames_ = 0;
  std::vector<Eigen::Vector3d> points_;  // right camera frame
};

}  // namespace nudge::geometry
