#pragma once
// Joint-space trajectories (Li 2008, appendix B.2): waypoints with linearly interpolated joint
// values (what the controller card's LM command executes), and single moves with a trapezoidal
// velocity profile. Both are sampled at any time t (seconds from the start of the motion);
// before the start they hold the first configuration, after the end the last.
#include <vector>

#include "nudge/robot/types.hpp"

namespace nudge::robot {

struct TimedJoints {
  double time = 0;  // seconds
  JointVector q = JointVector::Zero();
};

class JointTrajectory {
 public:
  virtual ~JointTrajectory() = default;
  virtual double duration() const = 0;
  virtual JointVector position(double t) const = 0;
  virtual JointVector velocity(double t) const = 0;
};

// Piecewise-linear interpolation between timed waypoints.
class LinearTrajectory : public JointTrajectory {
 public:
  // Times must be finite and strictly increasing, the first at 0; at least one waypoint.
  // Throws std::invalid_argument naming the offending waypoint.
  explicit LinearTrajectory(std::vector<TimedJoints> waypoints);

  // Times the waypoints so that on every segment the joint with the longest travel relative to its
  // speed limit moves at speed_scale times that limit, the others slower (all arrive together).
  static LinearTrajectory at_speed(const std::vector<JointVector>& waypoints,
                                   const JointVector& max_speed, double speed_scale = 1.0);

  double duration() const override;
  JointVector position(double t) const override;
  JointVector velocity(double t) const override;  // the segment's constant velocity
  const std::vector<TimedJoints>& waypoints() const { return waypoints_; }

 private:
  // Index of the segment [i, i+1] that contains t (t inside the trajectory's span).
  size_t segment_at(double t) const;

  std::vector<TimedJoints> waypoints_;
};

// A single point-to-point move along the straight joint-space line from start to goal, with a
// trapezoidal (or, for short moves, triangular) velocity profile. The path parameter is shared by
// all joints, so every joint starts, reaches cruise and stops at the same instants, and the motion
// stays on the straight line that check_joint_path() verifies. Each joint stays within its own
// speed and acceleration limit; the most constrained joint uses its limits fully.
class TrapezoidalMove : public JointTrajectory {
 public:
  // Limits must be finite and positive. Throws std::invalid_argument naming the joint otherwise.
  TrapezoidalMove(const JointVector& start, const JointVector& goal, const JointVector& max_speed,
                  const JointVector& max_acceleration);

  double duration() const override { return duration_; }
  JointVector position(double t) const override;
  JointVector velocity(double t) const override;
  JointVector acceleration(double t) const;
  double acceleration_time() const { return accel_time_; }  // the ramp at each end

 private:
  // Path parameter s(t) in [0, 1] and its derivatives.
  double path_position(double t) const;
  double path_velocity(double t) const;
  double path_acceleration(double t) const;

  JointVector start_, goal_, delta_;
  double path_accel_ = 0;  // d2s/dt2 during the ramps
  double peak_speed_ = 0;  // ds/dt while cruising
  double accel_time_ = 0;
  double duration_ = 0;
};

// Samples a trajectory every dt seconds, the last sample exactly at its end (for controllers
// that take timed joint targets, see driver.hpp).
std::vector<TimedJoints> sample_trajectory(const JointTrajectory& trajectory, double dt);

}  // namespace nudge::robot
