#include "backends.hpp"

#include <stdexcept>

namespace nudge::arm {

Backend make_backend(const std::string& name, const robot::ArmModel& model,
                     const robot::JointVector& initial, double gripper_speed) {
  Backend backend;
  backend.name = name;
  if (name == "sim") {
    auto arm = std::make_unique<robot::SimulatedArm>(model.limits, initial, gripper_speed);
    robot::SimulatedArm* raw = arm.get();
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
