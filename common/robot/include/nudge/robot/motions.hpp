#pragma once
// Task motions of the thesis: the robotic nudge (Li 2008, sec. 6.3, fig. 6.3-6.4), the grasp
// at a height above the table and the wrist rotation used to learn objects (sec. 7.2).
//
// All positions are in the arm base frame; heights are above the table plane of the SafetyConfig.
// Planners return joint waypoints meant to be executed with linear joint interpolation (the
// thesis' LM command, LinearTrajectory), already checked with check_joint_path().
#include <Eigen/Geometry>

#include <array>
#include <string>
#include <vector>

#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/robot/types.hpp"

namespace nudge::robot {

// The tool pointing straight down at the table (tool z = -base z) with its x axis at `yaw`
// radians about the base z axis.
Eigen::Matrix3d tool_down_orientation(double yaw);
Eigen::Isometry3d tool_down_pose(const Eigen::Vector3d& point, double yaw);

// The pushing tool for a push along the horizontal unit `direction`: pointing down and leaned by
// `tilt` radians, its point ahead of the flange along `lean` (a horizontal unit vector; the flange
// trails the tool point by tool_length * sin(tilt) along -lean). The tool's x axis stays in the
// vertical plane of the push, so the pad (which keeps the x axis' horizontal part, see sim) faces
// the push. tilt 0 is tool_down_orientation(atan2(direction)).
Eigen::Matrix3d tool_push_orientation(const Eigen::Vector3d& direction, const Eigen::Vector3d& lean,
                                      double tilt);

// A joint path, or why there is none.
struct JointPath {
  std::string reason;  // empty on success
  std::vector<JointVector> waypoints;
  bool ok() const { return reason.empty(); }
};

// Joint waypoints that move the tool point along the straight line from `from` to `to`
// (orientation interpolated by slerp), one IK solution every `step` metres (<= 0: only the end),
// all in the arm configuration of `start`, each nearest the previous one. Linear joint
// interpolation between them then stays close to the line (the thesis interpolated only between
// P0, P1 and P2).
// `start` must be the joints at `from`; it is the first waypoint, `to`'s solution the last.
JointPath cartesian_line(const ArmModel& model, const Eigen::Isometry3d& from,
                         const Eigen::Isometry3d& to, const JointVector& start, double step);

// Fig. 6.3: P0 above the target's approach point, P1 low beside the object, P2 just short of its
// symmetry axis (the effector never crosses it).
struct NudgeParams {
  double approach_height = 0.32;  // P0: tool point above the table, well above the tallest object
  // P1, P2: the tool point (the pad's centre) above the table. The pad is 30 mm tall, so at 30 mm
  // it spans 15-45 mm: near the table (the thesis' sponge), its lower edge above the objects'
  // rounded bases. At 10 mm, in the simulated world, a push laid down an empty bottle that pushes
  // from 20 to 50 mm up slide upright, and more nudges were refused for the leaned tool nearing the
  // table (docs/results/push_height.md).
  double push_height = 0.030;
  double start_distance = 0.110;  // Dmax: P1's horizontal distance from the target axis
  double stop_distance = 0.020;   // Dmin: P2 stops this far before the target axis
  double cartesian_step = 0.005;  // IK every this many metres along each line (see above)
  // The arm's links must keep clear of the pushed object. With the tool straight down the wrist
  // rides tool_length above the pad, beside the object: a bottle taller than that is struck by the
  // wrist and toppled forwards. So the planner keeps the forearm and wrist `link_clearance` away
  // from an upright cylinder of `object_radius` and `object_height` standing at the target (and
  // pushed along ahead of the pad, whose face is `pad_front` ahead of the tool point), and when
  // the straight-down tool cannot, leans it by `tool_tilt` so that the wrist trails the pad
  // (plan_nudge). object_height 0 leaves the check out.
  double object_height = 0.25;    // the tallest object to clear (P0's default is 70 mm above it)
  double object_radius = 0.045;
  double link_clearance = 0.01;
  double pad_front = 0.01;
  double tool_tilt = deg_to_rad(30.0);
};

// Thesis values from object sizes: P1 leaves `clearance` (20 mm) around the largest object,
// P2 pushes `overshoot` (10 mm) past where the smallest object is touched, P0 is
// `above_tallest` over the tallest object. Throws std::invalid_argument for impossible sizes.
NudgeParams nudge_params_for_objects(double largest_radius, double smallest_radius,
                                     double tallest_height, double clearance = 0.020,
                                     double overshoot = 0.010, double above_tallest = 0.07);

// Throws std::invalid_argument naming the field.
void validate(const NudgeParams& params);

// The least gap between the forearm (and upper arm) capsules or the wrist centre and the object
// of `params` standing at `target` and pushed along `direction` ahead of the tool point, when
// the arm is at `q`; negative when they overlap. Base frame.
double link_gap_to_pushed_object(const ArmModel& model, const SafetyConfig& safety,
                                 const NudgeParams& params, const Eigen::Vector3d& target,
                                 const Eigen::Vector3d& direction, const JointVector& q);

struct NudgePlan {
  std::string reason;  // empty on success
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // unit, horizontal
  double tilt = 0;                                       // the tool's lean, rad (0: straight down)
  Eigen::Vector3d lean = Eigen::Vector3d::UnitX();       // horizontal unit: the wrist trails along -lean
  std::array<Eigen::Isometry3d, 5> poses;  // P0, P1, P2, P1, P0: tool poses, base frame
  std::array<JointVector, 5> key_joints;   // their joint solutions
  std::vector<JointVector> waypoints;      // the whole joint path P0 ... P0, checked safe
  bool ok() const { return reason.empty(); }
};

// Plans a nudge of whatever stands at `target` (its x, y on the table) along `direction` (its
// horizontal part is used). The tool points down with its x axis along the push direction; when
// that would bring the forearm or wrist within params.link_clearance of the object (see
// NudgeParams), the tool leans by params.tool_tilt, the wrist trailing straight behind the pad or
// 45 or 90 deg to either side of that, the first lean whose path is safe and clear and whose P0
// the arm reaches from `seed` (where it is) along a safe straight joint line.
// The way back retraces the way out exactly (P2 -> P1 -> P0, as the thesis found necessary).
NudgePlan plan_nudge(const ArmModel& model, const SafetyConfig& safety,
                     const Eigen::Vector3d& target, const Eigen::Vector3d& direction,
                     const NudgeParams& params, const JointVector& seed);

// The two horizontal directions perpendicular to the ray from the camera to the target (the
// thesis pushes across the right camera's view so the object moves across the image).
std::array<Eigen::Vector3d, 2> directions_across_view(const Eigen::Vector3d& camera_position,
                                                      const Eigen::Vector3d& target);

// plan_nudge along the first of directions_across_view() that gives a safe plan.
NudgePlan plan_nudge_across_view(const ArmModel& model, const SafetyConfig& safety,
                                 const Eigen::Vector3d& target,
                                 const Eigen::Vector3d& camera_position,
                                 const NudgeParams& params, const JointVector& seed);

// Sec. 7.2.2: above the object's axis-table intersection, lower the open gripper to the grasp
// height, close (the caller), lift.
struct GraspParams {
  double approach_height = 0.32;  // tool point above the table before descending
  double lift_height = 0.30;      // tool point above the table after lifting
  double cartesian_step = 0.005;
};

struct GraspPlan {
  std::string reason;  // empty on success
  JointVector above = JointVector::Zero();   // joints at the approach pose
  std::vector<JointVector> descend;          // above -> grasp pose
  std::vector<JointVector> lift;             // grasp pose -> lifted
  bool ok() const { return reason.empty(); }
};

// `table_point`: where the object's axis meets the table (x, y used); `grasp_height`: tool point
// height above the table at the grasp; `yaw`: the tool x axis about the base z axis.
GraspPlan plan_grasp(const ArmModel& model, const SafetyConfig& safety,
                     const Eigen::Vector3d& table_point, double grasp_height, double yaw,
                     const GraspParams& params, const JointVector& seed);

// A parking pose inside the workspace: the tool pointing down `height` above the table,
// `radius` from the base axis along base x, in the thesis configuration, checked safe.
IkResult home_configuration(const ArmModel& model, const SafetyConfig& safety,
                            double radius = 0.25, double height = 0.32);

// Turns the tool about the last joint's axis by `angle` radians (vertical when the tool points
// down: sec. 7.2 takes a view every 30 deg). Fails with a reason if joint 6 would leave its limits.
IkResult rotate_wrist(const ArmModel& model, const JointVector& q, double angle);

}  // namespace nudge::robot
