#pragma once
// Plays an arm service's motion plan on the simulated PUMA 260's servos in one process, as the
// `arm` service's sim backend and the `world` service do over the bus: every Move on its
// trapezoidal profile, every Path at the planned speed, a joint target every `period` seconds.
// For experiments and tests that need the arm's own motions but not its processes (the pushed
// object's physics: how high to push, what a grasp does).
#include <functional>

#include "nudge/robot/command_planner.hpp"
#include "nudge/sim/world.hpp"

namespace nudge::sim {

struct MotionPlayback {
  double period = 0.01;         // s between joint targets (the arm service publishes at 100 Hz)
  double gripper_time = 1.0;    // s a gripper step is given to open or close
  // Called after every period of physics (for watching an object during the motion).
  std::function<void(const World&)> each_period;
};

// Plays `plan` (ok(), planned from the world's current arm joints with `config`) on `world`, whose
// tools are mounted on the arm. Throws std::invalid_argument for a refused plan or a bad period,
// SimError for a world without an arm.
void play_motion(World& world, const robot::PlannerConfig& config, const robot::MotionPlan& plan,
                 const MotionPlayback& playback = {});

// Plans `command` as the arm service does (robot::plan_command from the joints the servos are
// sent to) and plays it when it plans. Returns the plan: a refused one moved nothing.
robot::MotionPlan plan_and_play(World& world, const robot::PlannerConfig& config, const robot::Command& command,
                                const MotionPlayback& playback = {});

}  // namespace nudge::sim
