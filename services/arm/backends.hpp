#pragma once
// The arm service's backends: whatever executes the checked joint targets (robot::ArmDriver).
//
//   sim   robot::SimulatedArm: a kinematic arm inside this service that follows its targets exactly
//         and opens/closes its gripper at a finite speed. The MuJoCo world follows the ARM_STATE the
//         service publishes from it, so the simulated arm is exactly what the world shows.
//   fake  robot::FakeDriver as it is (instant gripper): dry runs and tests.
//
// Both run on the service's clock (wall, simulated or log time): `advance` moves them forward.
// A hardware driver runs on its own real time: it implements robot::ArmDriver, its `advance`
// does nothing, and the service must run on --clock wall (docs/robot.md, "The arm service").
#include <functional>
#include <memory>
#include <string>

#include "nudge/robot/driver.hpp"
#include "nudge/robot/puma260.hpp"

namespace nudge::arm {

struct Backend {
  std::string name;
  std::unique_ptr<robot::ArmDriver> driver;
  std::function<void(double seconds)> advance;  // moves a simulated backend's clock forward
};

// "sim" or "fake"; throws std::invalid_argument naming the choices otherwise.
Backend make_backend(const std::string& name, const robot::ArmModel& model,
                     const robot::JointVector& initial, double gripper_speed);

}  // namespace nudge::arm
