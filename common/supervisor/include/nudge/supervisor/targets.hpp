#pragma once
// Which candidate to nudge next (thesis sec. 6.2-6.3, fig. 6.2): the candidate nearest the right
// camera that is nudgeable, i.e. the arm can plan the push (reach, joint limits, table, workspace
// ring, self-collision: the robot library's own checks, the same the arm service applies) and the
// push would not touch another candidate. Every candidate passed over gets its reason.
#include <Eigen/Core>

#include <string>
#include <vector>

#include "nudge/robot/motions.hpp"

namespace nudge::supervisor {

// Where the arm stands in the world frame (docs/robot.md, "Frames"): its base on the world z axis
// `base_height` above the table top, turned `base_yaw` about z.
struct ArmSetup {
  robot::ArmModel model = robot::puma260();
  robot::SafetyConfig safety;
  robot::NudgeParams nudge;
  double base_height = 0.33;
  double base_yaw = 0.0;

  // The safety checks with the table where the base height puts it.
  robot::SafetyConfig safety_config() const;
  // Where the arm parks (the arm service's COMMAND_HOME pose): the planner's seed before any ARM_STATE.
  robot::JointVector home() const;
  Eigen::Vector3d point_to_base(const Eigen::Vector3d& world) const;
  Eigen::Vector3d direction_to_base(const Eigen::Vector3d& world) const;
  Eigen::Vector3d direction_to_world(const Eigen::Vector3d& base) const;
};

struct TargetParams {
  double object_radius = 0.045;   // the largest expected object (thesis: mugs, bottles)
  double travel = 0.04;           // how far a nudged object may slide beyond P2
  double explored_radius = 0.03;  // a candidate this close to a place already explored is skipped
};

struct Candidate {
  int index = 0;                   // in the CANDIDATES message
  Eigen::Vector3d position;        // world frame, on the table
  int support = 0;                 // intersects in its cluster
};

struct Rejection {
  int index = 0;
  Eigen::Vector3d position;
  std::string reason;
};

struct TargetChoice {
  bool found = false;
  Candidate target;
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  // push direction, world frame, horizontal
  robot::NudgePlan plan;                                  // base frame (for pictures and checks)
  std::vector<Rejection> rejected;                        // every candidate passed over, and why
  std::string note;  // set when the push was accepted although it may touch another candidate
};

// Candidates nearest the right camera first; the first nudgeable one is chosen. `explored` are
// places already nudged (where a candidate stood, where a nudged object came to rest); `empty` are
// places a nudge found nothing at (phantoms): they are no obstacle to other pushes.
// Beyond the thesis (one object per scene): on a crowded table every push may pass near another
// candidate, many of them phantoms between two objects. When no push is clear, the nearest
// candidate the arm can reach is nudged anyway (the nudge is gentle and short) and `note` says
// which candidate it may touch; the strict rule still decides whenever it can.
TargetChoice choose_target(const std::vector<Candidate>& candidates, const std::vector<Eigen::Vector3d>& explored,
                           const std::vector<Eigen::Vector3d>& empty, const Eigen::Vector3d& right_camera,
                           const ArmSetup& arm, const robot::JointVector& seed, const TargetParams& params = {});

// Why pushing `target` along `direction` would touch `other` (empty if it would not): the pad's
// sweep from P1 to P2 and the object's slide beyond, widened by two object radii.
std::string push_conflict(const Eigen::Vector3d& target, const Eigen::Vector3d& direction,
                          const Eigen::Vector3d& other, const ArmSetup& arm, const TargetParams& params);

}  // namespace nudge::supervisor
