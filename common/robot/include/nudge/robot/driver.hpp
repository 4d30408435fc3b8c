#pragma once
// What the arm service needs from a backend, and a fake one for tests.
//
// A hardware driver (the thesis' PCI motion card driving AMC amplifiers, appendix B.2) or the
// simulation backend implements ArmDriver. The arm service does everything else itself, whatever
// the backend: kinematics, trajectory generation and the safety checks of safety.hpp. A driver
// still refuses targets outside the joint limits it was given: the last line of defence.
//
// Threading: the arm service calls a driver from one thread; implementations need no locking
// unless they run their own threads.
#include <string>
#include <vector>

#include "nudge/robot/puma260.hpp"
#include "nudge/robot/trajectory.hpp"
#include "nudge/robot/types.hpp"

namespace nudge::robot {

struct JointState {
  double time = 0;  // seconds on the driver's clock when the joints were read
  JointVector position = JointVector::Zero();  // radians, encoder readings converted
  JointVector velocity = JointVector::Zero();  // rad/s
  bool moving = false;                         // a motion is still being executed
  double gripper_opening = 0;                  // metres between the fingers
};

class ArmDriver {
 public:
  virtual ~ArmDriver() = default;

  // Starts executing timed joint targets, replacing any motion in progress. Times are seconds from
  // now, strictly increasing, the first > 0; the controller moves linearly in joint space from the
  // current position to the first target and between targets (the thesis' LM command). Returns an
  // empty string when accepted, otherwise why the targets were refused (nothing moves then).
  virtual std::string send_joint_targets(const std::vector<TimedJoints>& targets) = 0;

  // The latest joint readings. Never blocks for long: reads the encoders or the last message.
  virtual JointState read_joint_state() = 0;

  // Halts at once and holds the current position; later targets are accepted again.
  virtual void stop() = 0;

  // Opens or closes the gripper. Returns an empty string when accepted, otherwise why not.
  virtual std::string open_gripper() = 0;
  virtual std::string close_gripper() = 0;
};

// An in-memory arm for tests and dry runs: follows targets exactly, on a clock that only moves
// when advance() is called, so tests are deterministic and never sleep.
class FakeDriver : public ArmDriver {
 public:
  static constexpr double kGripperOpen = 0.10;  // metres

  explicit FakeDriver(JointLimits limits, const JointVector& initial = JointVector::Zero());

  std::string send_joint_targets(const std::vector<TimedJoints>& targets) override;
  JointState read_joint_state() override;
  void stop() override;
  std::string open_gripper() override;
  std::string close_gripper() override;

  // Moves the fake clock forward (seconds, non-negative).
  void advance(double seconds);
  double now() const { return now_; }
  int accepted_commands() const { return accepted_commands_; }
  int stop_count() const { return stop_count_; }

 private:
  JointVector position_at(double time) const;

  JointLimits limits_;
  double now_ = 0;
  // The motion in progress, on the fake clock: the position at its start, then the targets.
  std::vector<TimedJoints> motion_;
  double gripper_opening_ = kGripperOpen;
  int accepted_commands_ = 0;
  int stop_count_ = 0;
};

// The simulated PUMA 260 of the arm service's `sim` backend: a FakeDriver whose gripper opens and
// closes at a finite speed (`moving` while it travels), on the same advance() clock. The MuJoCo
// world follows the joints and the opening the arm service publishes from it (docs/sim.md).
class SimulatedArm : public FakeDriver {
 public:
  // Throws std::invalid_argument unless gripper_speed (m/s) is positive and finite.
  SimulatedArm(JointLimits limits, const JointVector& initial, double gripper_speed);

  JointState read_joint_state() override;  // `moving` also while the gripper travels
  void stop() override;                    // the gripper halts too
  std::string open_gripper() override;
  std::string close_gripper() override;
  void advance(double seconds);

 private:
  double gripper_speed_;  // m/s
  double gripper_opening_ = kGripperOpen;
  double gripper_target_ = kGripperOpen;
};

}  // namespace nudge::robot
