#pragma once
// Where to grasp a nudged object (thesis sec. 7.2.2, fig. 7.3-7.4): the top of the object in each
// camera's segmentation (the post-nudge symmetry line meets the top of the mask's largest
// 8-connected blob), triangulated; the triangulated top lies on the rear rim of the object, too
// high by d = r tan(theta) (r: the top's radius, theta: the camera's angle of view over the table),
// and the object's top is that much lower. The fingers close a fixed depth below that top, where
// a bottle's sides are vertical (its shoulder, neck and cap slope, and a squeeze on a slope pushes
// the object out of the fingers), never below half the object's height. Also the box a held object occupies in the right still
// (the learner's background pruning, sec. 7.3).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <optional>
#include <string>

#include "nudge/supervisor/scene.hpp"
#include "nudge/symmetry/detector.hpp"

namespace nudge::supervisor {

struct GraspTargetParams {
  // r in d = r tan(theta). The thesis' objects have tops of 30-90 mm radius and it lowers by the
  // middle value (36 mm at 30 deg: +-18 mm tolerance, which its foam pads exceed).
  double top_radius_m = 0.06;
  // The tool point (the middle of the fingers, which span +-19 mm) this far below the estimated
  // top. High enough that the fingers hide little of what the object shows (sim bottle: label at
  // 30-120 mm of its 200 mm), low enough that both rows of faces close on vertical sides: a
  // bottle's top 75 mm narrow to the neck and cap, and a grip there slips out (the gripper test
  // measures both). The estimated tops of the learning runs lay 6-30 mm below the true 200 mm, so
  // the tool point lands at 105-129 mm, the lower row on the body, the fingers over the label's top
  // 15-20 mm (at 90 mm below they covered its upper half); the thesis' foam pads gripped whatever
  // they met.
  double grip_depth_m = 0.065;
  double min_grip_fraction = 0.5;  // a short object is gripped no lower than this part of its height
  double min_grasp_height_m = 0.03;  // the fingers never close lower (the table)
  double max_object_height_m = 0.35; // a taller triangulated top is a mismatch, not an object
};

// What a segmentation mask (CV_8U, non-zero = object) shows along the object's symmetry line (the
// post-nudge line, in the mask's coordinates): walking down the line from the image's top, the
// first and the last pixel of the mask's largest 8-connected blob (the object's top, and the front
// of its base), and the blob's widest row in the lowest fifth between them (its base's width: the
// sides are vertical there; the front pixel is the base ellipse's lowest point, of no width). A
// row lopsided about the line (one side longer by more than 15 % of the width) is read as twice
// its narrower side: a mug's handle, on one side, widened the base and put the foot 24 mm too far
// (development s03) before.
// Nothing when the mask is empty, the line is near horizontal (no standing object's axis) or misses
// the blob. The mask's blobs are labelled once for all three.
struct MaskOnLine {
  cv::Point2d top, front;
  int base_width_px = 0;
  int widest_px = 0;  // the widest row from the top to the front (read the same way)
  cv::Size size;      // the mask's
};
std::optional<MaskOnLine> read_mask_on_line(const cv::Mat& mask, const symmetry::Line& line);

// The object's top in the mask: read_mask_on_line's `top`.
std::optional<cv::Point2d> object_top(const cv::Mat& mask, const symmetry::Line& line);

// The foot (world, z = 0) of an upright object from the right camera's segmentation alone: the
// front of its base's ray meets the calibrated table there, and the axis stands the base's radius
// (half its width, at that depth) farther along the ray. One camera and the table plane: unlike
// the stereo axes, a left line paired with the wrong right line cannot move it along the ray.
// Nothing when the ray misses the table, or when the base is narrower than kMinBaseShareOfWidest
// of the mask's widest row: the segmentation missed the object's lower part (a white bottle on
// the demo's table kept a 2 cm sliver of its lowest quarter, and its foot came out 21 mm short,
// the settled axes 6 mm off). The objects' bases are as wide as their bodies; a cup's tapers to
// 0.7 of its rim.
constexpr double kMinBaseShareOfWidest = 0.5;
std::optional<Eigen::Vector3d> foot_from_mask(const SceneGeometry& scene, const MaskOnLine& right_mask);
std::optional<Eigen::Vector3d> foot_from_mask(const SceneGeometry& scene, const cv::Mat& mask, const symmetry::Line& line);

// Whether the mask's front (its lowest pixel on the line) lies where an upright column `radius`
// wide and `height` tall standing at `place` (world), nearer the right camera than the object
// (`stands_at`, as another measure puts it: the settled axes), hides what is below it: the mask
// then ends at that object's outline, not at the base, and the foot read from it lies too far
// along the ray (the demo's white bottle behind the mug: 9 cm).
bool mask_front_hidden_by(const SceneGeometry& scene, const MaskOnLine& right_mask, const Eigen::Vector3d& stands_at,
                          const Eigen::Vector3d& place, double radius, double height);

// The width (metres) of the mask's largest blob (the right camera's segmentation, CV_8U) at
// `height` above the table on the upright axis through `foot` (world): the blob's row there,
// first to last pixel, at the axis' depth. What the fingers closing at that height should meet.
// Nothing when the point is out of the image or the blob has no pixel in that row.
std::optional<double> object_width_at(const SceneGeometry& scene, const cv::Mat& right_mask, const Eigen::Vector3d& foot,
                                      double height);

struct GraspTarget {
  std::string reason;                              // why there is none; empty when ok
  Eigen::Vector3d foot = Eigen::Vector3d::Zero();  // where the axis meets the table, world
  Eigen::Vector3d top = Eigen::Vector3d::Zero();   // the triangulated top, world
  double overestimate_m = 0;                       // d = r tan(theta)
  double top_height_m = 0;                         // the estimated top above the table: top.z() - d
  double grasp_height_m = 0;                       // tool point above the table at the grasp
  bool ok() const { return reason.empty(); }
};

// The grasp from the object's top in both stills (pixels at `still_size`) and its foot on the
// table (world, from the settled axes); the grasp height by grip_height(). Fails with a reason when the tops do not triangulate, the
// top is below the minimum grasp height or above any object.
// The tool point's height for an object whose top is `top_height` above the table:
// max(top_height - grip_depth_m, min_grip_fraction * top_height).
double grip_height(double top_height, const GraspTargetParams& params);

GraspTarget grasp_target(const SceneGeometry& scene, const cv::Point2d& left_top, const cv::Point2d& right_top,
                         cv::Size still_size, const Eigen::Vector3d& foot, const GraspTargetParams& params = {});

// The box (clamped to the image) a vertical cylinder of `radius` spanning heights [bottom, top]
// (world z) about the vertical through `centre` occupies in the right camera at `size`; empty
// when it is behind the camera or outside the image.
cv::Rect cylinder_box(const SceneGeometry& scene, const Eigen::Vector3d& centre, double radius, double bottom,
                      double top, cv::Size size);

}  // namespace nudge::supervisor
