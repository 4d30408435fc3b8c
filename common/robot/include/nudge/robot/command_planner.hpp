#pragma once
// Plans and checks an arm command completely before anything moves: the arm service runs every
// command through plan_command(), and a supervisor can call it first to know whether a nudge or a
// grasp would be accepted (and why not) before asking the arm for it.
//
// Commands are in the WORLD (table) frame of docs/sim.md; the planner converts them to the arm's
// base frame with the configuration's BaseFrame (workspace.hpp). A plan is a list of steps, each
// checked as the driver will execute it from the arm's current joints: IK reachability, joint
// limits, table clearance, self-collision, the workspace ring, every joint-space segment sampled
// densely. A refused plan names the first step that fails and why.
#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "nudge/robot/motions.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/robot/types.hpp"
#include "nudge/robot/workspace.hpp"

namespace nudge::robot {

constexpr double kMinSpeedScale = 0.01;  // a floor keeps a tiny scale from asking for days of samples

struct PlannerConfig {
  ArmModel model = puma260();
  SafetyConfig safety;         // its table_z is ignored: the table is where `base` says
  BaseFrame base;
  NudgeParams nudge;           // defaults for the fields a nudge command leaves at 0
  GraspParams grasp;
  double speed_scale = 0.5;    // for commands that leave speed_scale at 0
  double home_radius = 0.25;   // home: tool point this far out along base x,
  double home_height = 0.32;   // this high above the table, pointing down
};

// The default configuration with the workspace's tool, base, table and ring.
PlannerConfig planner_config(const Workspace& workspace);

// Throws std::invalid_argument naming the field.
void validate(const PlannerConfig& config);

enum class CommandKind { MoveJoints, MovePose, Nudge, Grasp, Place, OpenGripper, CloseGripper, RotateWrist, Home };

// "nudge", "move to pose", ...: for reasons.
std::string command_name(CommandKind kind);

// One command, world frame, as arm_command_t carries it. Fields a command does not use are
// ignored; 0 in an optional number means "the configuration's default".
struct Command {
  CommandKind kind = CommandKind::Home;
  std::vector<double> joints;                                  // MoveJoints: 6, radians
  Eigen::Vector3d target_position = Eigen::Vector3d::Zero();   // MovePose, Nudge, Grasp, Place
  // (w, x, y, z). MovePose: must be a unit quaternion. Grasp/Place: the tool x axis' heading
  // about the vertical; all zero (unset) means world x.
  Eigen::Vector4d target_orientation = Eigen::Vector4d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::Zero();         // Nudge: push direction
  double height = 0;            // Nudge: push height (0: default); Grasp/Place: tool height, > 0
  double approach_height = 0;   // Nudge P0 (0: default)
  double start_distance = 0;    // Nudge Dmax (0: default)
  double stop_distance = 0;     // Nudge Dmin (0: default)
  double object_height = 0;     // Nudge: the pushed object's height the links clear (0: default)
  double angle = 0;             // RotateWrist, radians
  double speed_scale = 0;       // fraction of the joint speed limits (0: default)
};

// One stage of a planned motion, executed in order by the arm service.
struct MotionStep {
  enum class Kind { Move, Path, OpenGripper, CloseGripper };
  Kind kind = Kind::Move;
  std::string what;                // for reasons: "the move to P0"
  JointVector goal = JointVector::Zero();  // Move: trapezoidal profile from the joints before
  std::vector<JointVector> path;   // Path: waypoints, linear joint interpolation, from where the arm is
  double speed_scale = 1.0;
};

struct MotionPlan {
  std::string reason;      // empty when the command can be executed
  bool malformed = false;  // refused for its content (bad numbers, wrong joint count), not for safety
  std::vector<MotionStep> steps;
  bool ok() const { return reason.empty(); }
};

// Plans `command` from the arm's `current` joints and checks every step (check_steps). Never
// throws for a bad command: the plan carries the refusal reason.
MotionPlan plan_command(const PlannerConfig& config, const Command& command, const JointVector& current);

// Checks a step list from `current` as a driver will execute it: every Move's goal and straight
// joint-space line, every Path's continuity and segments. Returns the first failure, or "".
std::string check_steps(const ArmModel& model, const SafetyConfig& safety,
                        const std::vector<MotionStep>& steps, const JointVector& current);

// A pose from a position and a (w, x, y, z) quaternion. False when a number is not finite or the
// quaternion is not of unit length (within 1e-3; it is then normalised exactly).
bool pose_from_parts(const Eigen::Vector3d& position, const Eigen::Vector4d& wxyz, Eigen::Isometry3d* pose);

}  // namespace nudge::robot
