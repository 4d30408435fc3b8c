#include <cmath>
#include <stdexcept>
#include <utility>

#include "nudge/robot/driver.hpp"

namespace nudge::robot {

SimulatedArm::SimulatedArm(JointLimits limits, const JointVector& initial, double gripper_speed)
    : FakeDriver(std::move(limits), initial), gripper_speed_(gripper_speed) {
  if (!(gripper_speed > 0) || !std::isfinite(gripper_speed)) {
    throw std::invalid_argument("gripper speed must be positive and finite");
  }
}

JointState SimulatedArm::read_joint_state() {
  JointState state = FakeDriver::read_joint_state();
  state.gripper_opening = gripper_opening_;
  state.moving = state.moving || gripper_opening_ != gripper_target_;
  return state;
}

void SimulatedArm::stop() {
  FakeDriver::stop();
  gripper_target_ = gripper_opening_;
}

std::string SimulatedArm::open_gripper() {
  gripper_target_ = kGripperOpen;
  return "";
}

std::string SimulatedArm::close_gripper() {
  gripper_target_ = 0.0;
  return "";
}

void SimulatedArm::advance(double seconds) {
  FakeDriver::advance(seconds);  // validates `seconds`
  const double travel = gripper_speed_ * seconds;
  const double gap = gripper_target_ - gripper_opening_;
  gripper_opening_ = std::fabs(gap) <= travel ? gripper_target_ : gripper_opening_ + std::copysign(travel, gap);
}

}  // namespace nudge::robot
