#pragma once
// Forward kinematics (Li 2008, eq. B.1-B.2) and closed-form inverse kinematics (eq. B.4-B.9,
// generalised to all eight arm configurations) of the PUMA 260.
//
// The inverse kinematics relies on the PUMA structure of Table B.1 (spherical wrist, only a2, d3
// and d4 non-zero); it reads a2, d3 and d4 from the model and throws std::invalid_argument for a
// model of another shape. It never returns NaN: every failure carries a reason.
#include <Eigen/Geometry>

#include <string>
#include <vector>

#include "nudge/robot/puma260.hpp"
#include "nudge/robot/types.hpp"

namespace nudge::robot {

// Eq. B.1: the transform across link i for joint angle theta.
Eigen::Isometry3d dh_transform(const DhLink& link, double theta);

// Eq. B.2: T_w = T1 ... T6, the flange (wrist centre) pose in the base frame.
Eigen::Isometry3d flange_pose(const ArmModel& model, const JointVector& q);

// The tool point pose in the base frame: flange_pose * model.tool.
Eigen::Isometry3d forward_kinematics(const ArmModel& model, const JointVector& q);

// Points of the arm that safety checks look at, in the base frame.
struct ArmPoints {
  Eigen::Vector3d elbow;  // origin of DH frame 2 (end of the upper arm)
  Eigen::Vector3d wrist;  // wrist centre (flange origin)
  Eigen::Vector3d tool;   // tool point
};
ArmPoints arm_points(const ArmModel& model, const JointVector& q);

// The eight solutions of a pose, named as in Paul & Zhang (1986).
enum class Shoulder { Right, Left };  // Right: the thesis' theta1 = atan(Py/Px) + asin(d3/r)
enum class Elbow { Up, Down };        // Up: the elbow lies above the shoulder-wrist line
enum class WristFlip { NoFlip, Flip };  // NoFlip: theta4 within [-90, 90] deg

struct ArmConfiguration {
  Shoulder shoulder = Shoulder::Right;
  Elbow elbow = Elbow::Up;
  WristFlip wrist = WristFlip::NoFlip;
  bool operator==(const ArmConfiguration& o) const {
    return shoulder == o.shoulder && elbow == o.elbow && wrist == o.wrist;
  }
};

// The configuration the thesis' solution picks: right arm, elbow up, wrist no-flip.
constexpr ArmConfiguration kThesisConfiguration{};

// All eight configurations, the thesis' first.
std::vector<ArmConfiguration> all_configurations();

// Which configuration a joint vector is in (inverse of the choice inverse_kinematics makes).
ArmConfiguration configuration_of(const ArmModel& model, const JointVector& q);

std::string to_string(const ArmConfiguration& configuration);

enum class IkFailure {
  None,
  InvalidPose,        // non-finite numbers or a rotation that is not orthonormal
  InsideInnerRadius,  // wrist centre closer to the joint 1 axis than the shoulder offset d3
  OutOfReach,         // wrist centre farther from the shoulder than a2 + d4
  JointLimit,         // solvable, but a joint would leave its limits (e.g. J3 folded too far)
  WristSingular,      // theta5 ~ 0 and the options ask to refuse wrist singularities
  Unsafe,             // reachable, but refused by a safety check (see safety.hpp)
};

struct IkOptions {
  ArmConfiguration configuration = kThesisConfiguration;
  // Joints 1, 4 and 6 may have several 2*pi aliases within their limits: the one nearest the seed
  // wins. At a wrist singularity theta4 keeps the seed's value.
  JointVector seed = JointVector::Zero();
  // |sin(theta5)| below this counts as a wrist singularity (flagged, or refused; see below).
  double wrist_singularity_tolerance = 1e-3;
  bool refuse_wrist_singularity = false;
};

struct IkResult {
  IkFailure failure = IkFailure::None;
  std::string reason;   // empty on success
  JointVector q = JointVector::Zero();  // valid only on success
  bool wrist_singular = false;
  bool ok() const { return failure == IkFailure::None; }
};

// Joint angles that put the flange (wrist centre) at `flange` in the requested configuration.
IkResult inverse_kinematics_flange(const ArmModel& model, const Eigen::Isometry3d& flange,
                                   const IkOptions& options = {});

// Joint angles that put the tool point at `tool_pose` (base frame) in the requested configuration.
IkResult inverse_kinematics(const ArmModel& model, const Eigen::Isometry3d& tool_pose,
                            const IkOptions& options = {});

// Every configuration's solution that lies within the joint limits.
std::vector<JointVector> all_inverse_kinematics(const ArmModel& model,
                                                const Eigen::Isometry3d& tool_pose,
                                                const JointVector& seed = JointVector::Zero());

// The seed's own configuration if its solution is within limits; otherwise the solution within
// limits nearest the seed (largest-joint-change metric) over all eight configurations. Fails with
// the seed configuration's reason when none exists.
IkResult nearest_inverse_kinematics(const ArmModel& model, const Eigen::Isometry3d& tool_pose,
                                    const JointVector& seed);

// Largest absolute joint difference, radians: the distance used to pick the nearest solution.
double joint_distance(const JointVector& a, const JointVector& b);

}  // namespace nudge::robot
