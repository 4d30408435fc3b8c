#include "backends.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace nudge::arm {

SimulatedArm::SimulatedArm(robot::JointLimits limits, const robot::JointVector& initial,
                           double gripper_speed)
    : FakeDriver(std::move(limits), initial), gripper_speed_(gripper_speed) {
  if (!(gripper_speed > 0) || !std::isfinite(gripper_speed)) {
    throw std::invalid_argument("gripper speed must be positive and finite");
  }
}

robot::JointState SimulatedArm::read_joint_state() {
  robot::JointState state = FakeDriver::read_joint_state();
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
  gripper_opening_ = std::fabs(gap) <= travel ? gripper_target_
                                              : gripper_opening_ + std::copysign(travel, gap);
}

Backend make_backend(const std::string& name, const robot::ArmModel& model,
                     const robot::JointVector& initial, double gripper_speed) {
  Backend backend;
  backend.name = name;
  if (name == "sim") {
    auto arm = std::make_unique<SimulatedArm>(model.limits, initial, gripper_speed);
    SimulatedArm* raw = arm.get();
    backend.advance = [raw](double seconds) { raw->advance(seconds); };
    backend.driver = std::move(arm);
  } else if (name == "fake") {
    auto arm = std::make_unique<robot::FakeDriver>(model.limits, initial);
    robot::FakeDriver* raw = arm.get();
    backend.advance = [raw](double seconds) { raw->advance(seconds); };
    backend.driver = std::move(arm);
  } else {
    throw std::invalid_argument("unknown backend '" + name + "' (known: sim, fake)");
  }
  return backend;
}

}  // namespace nudge::arm
