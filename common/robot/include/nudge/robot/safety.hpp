#pragma once
// Safety checks the arm service applies to every motion, whatever the backend (sim or hardware):
// joint limits, the workspace ring around the arm base (Li 2008, sec. 6.3: roughly 150-350 mm),
// clearance above the table, self-collision, and densely sampled joint-space paths. Each check
// returns a reason when it fails. All positions are in the arm base frame (see puma260.hpp).
#include <Eigen/Geometry>

#include <vector>

#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/robot/trajectory.hpp"
#include "nudge/robot/types.hpp"
#include "nudge/robot/workspace.hpp"

namespace nudge::robot {

struct SafetyConfig {
  // Height of the table plane in the base frame (the shoulder is the origin, so this is
  // negative). The table, margin and ring default to the Workspace's (apply_workspace()).
  double table_z = -Workspace{}.shoulder_height;
  double table_margin = Workspace{}.table_margin;  // tool point, wrist centre and elbow stay this far above the table
  double ring_inner = Workspace{}.ring_inner;      // tool point's distance from the joint 1 axis, metres
  double ring_outer = Workspace{}.ring_outer;
  bool enforce_ring = true;     // the arm service may lift this for parking poses outside the ring
  double path_step = deg_to_rad(1.0);  // largest joint change between checked path samples
  // Self-collision: the links as capsules (a segment and a radius), metres. Assumed sizes of a
  // PUMA 260 carrying a small gripper or the nudging sponge; measure the real arm and tool.
  bool check_self_collision = true;
  double pedestal_radius = 0.065;   // the column from the shoulder down to the table
  double upper_arm_radius = 0.045;  // shoulder to elbow, beside the base axis by the offset d3
  double forearm_radius = 0.035;    // elbow to wrist centre
  double tool_radius = 0.035;       // wrist centre to tool point (gripper, bracket, sponge)
  double self_clearance = 0.01;     // extra gap kept between capsules that must not touch
};

// Throws std::invalid_argument naming the field when the configuration makes no sense.
void validate(const SafetyConfig& config);

CheckResult check_joint_limits(const ArmModel& model, const JointVector& q);

// The tool point's horizontal distance from the base axis must lie within the ring.
CheckResult check_workspace_ring(const SafetyConfig& config, const Eigen::Vector3d& tool_point);

// Tool point, wrist centre and elbow above table_z + table_margin.
CheckResult check_table_clearance(const ArmModel& model, const SafetyConfig& config,
                                  const JointVector& q);

// The links as capsules in the base frame (see SafetyConfig), for the self-collision check and
// for pictures.
struct Capsule {
  Eigen::Vector3d a, b;
  double radius = 0;
};
struct ArmCapsules {
  Capsule pedestal, upper_arm, forearm, tool;
};
ArmCapsules arm_capsules(const ArmModel& model, const SafetyConfig& config, const JointVector& q);

// An object standing upright on the table that the arm must keep clear of (base frame; the
// place's x, y are used): a capsule-shaped column of `radius` from the table up to `height` above
// it, so its top is taken `radius` higher than a flat one (a gap on the safe side).
struct StandingObject {
  Eigen::Vector3d place = Eigen::Vector3d::Zero();
  double radius = 0;
  double height = 0;
};

// The least gap between the moving links (upper arm, forearm, tool with its pad) at `q` and
// `object`; negative when they overlap. The pedestal does not move and is not counted.
double link_gap_to_standing_object(const ArmModel& model, const SafetyConfig& config, const StandingObject& object,
                                   const JointVector& q);

// The least such gap along a piecewise-linear joint path, sampled as check_joint_path samples
// it (no joint moves more than config.path_step between samples). Infinity for no waypoints.
double least_link_gap_along(const ArmModel& model, const SafetyConfig& config, const StandingObject& object,
                            const std::vector<JointVector>& waypoints);

// The pairs of links that are not joined to each other: the forearm and the tool against the
// pedestal, the tool against the upper arm. Names the pair and their gap when they come closer
// than config.self_clearance. (The tool cannot fold back onto the forearm: joint 5 stops at
// +-100 deg.) Passes when config.check_self_collision is off.
CheckResult check_self_collision(const ArmModel& model, const SafetyConfig& config, const JointVector& q);

// Closest distance between the segments [a0, a1] and [b0, b1] (either may be a point).
double segment_distance(const Eigen::Vector3d& a0, const Eigen::Vector3d& a1, const Eigen::Vector3d& b0,
                        const Eigen::Vector3d& b1);

// Joint limits, then table clearance, then self-collision, then (if enforced) the workspace ring.
CheckResult check_configuration(const ArmModel& model, const SafetyConfig& config,
                                const JointVector& q);

// The straight joint-space line from `from` to `to`, sampled so that no joint moves more than
// config.path_step between samples (both ends included). Names the first unsafe fraction.
CheckResult check_joint_path(const ArmModel& model, const SafetyConfig& config,
                             const JointVector& from, const JointVector& to);

// Every segment of a piecewise-linear joint path (e.g. LinearTrajectory waypoints).
CheckResult check_joint_path(const ArmModel& model, const SafetyConfig& config,
                             const std::vector<JointVector>& waypoints);

// A tool pose the arm can reach safely: the IK solution nearest the seed, refused with a reason
// when it is unreachable or fails check_configuration (the arm service's move-to-pose).
IkResult safe_inverse_kinematics(const ArmModel& model, const SafetyConfig& config,
                                 const Eigen::Isometry3d& tool_pose, const JointVector& seed);

}  // namespace nudge::robot
