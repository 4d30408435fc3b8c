#include "nudge/sim/arm_motion.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "nudge/robot/driver.hpp"
#include "nudge/robot/trajectory.hpp"

namespace nudge::sim {
namespace {

std::array<double, 6> as_array(const robot::JointVector& q) {
  std::array<double, 6> a;
  for (int j = 0; j < 6; ++j) a[j] = q[j];
  return a;
}

robot::JointVector targets_of(const World& world) {
  const std::array<double, 6> a = world.arm_targets();
  return Eigen::Map<const robot::JointVector>(a.data());
}

// Sends the trajectory's samples (after its start) as servo targets, one period of physics each.
void play_trajectory(World& world, const robot::JointTrajectory& trajectory, const MotionPlayback& playback) {
  for (const robot::TimedJoints& sample : robot::sample_trajectory(trajectory, playback.period)) {
    if (sample.time <= 0) continue;
    world.set_arm_targets(as_array(sample.q));
    world.step_for(playback.period);
    if (playback.each_period) playback.each_period(world);
  }
}

void hold_for(World& world, double seconds, const MotionPlayback& playback) {
  for (double t = 0; t < seconds; t += playback.period) {
    world.step_for(playback.period);
    if (playback.each_period) playback.each_period(world);
  }
}

}  // namespace

void play_motion(World& world, const robot::PlannerConfig& config, const robot::MotionPlan& plan,
                 const MotionPlayback& playback) {
  if (!plan.ok()) throw std::invalid_argument("play_motion: the plan was refused: " + plan.reason);
  if (!(playback.period > 0 && playback.period <= 1) || !(playback.gripper_time >= 0))
    throw std::invalid_argument("play_motion: period must lie in (0, 1] s and gripper_time must not be negative");
  if (!world.has_arm()) throw SimError(world.scene().source + ": play_motion needs an arm in the scene");
  // The servos follow targets: the trajectories start from the targets the plan was made from.
  robot::JointVector at = targets_of(world);
  for (const robot::MotionStep& step : plan.steps) {
    switch (step.kind) {
      case robot::MotionStep::Kind::Move: {
        const robot::TrapezoidalMove move(at, step.goal, step.speed_scale * config.model.max_speed,
                                          step.speed_scale * config.model.max_acceleration);
        play_trajectory(world, move, playback);
        at = step.goal;
        break;
      }
      case robot::MotionStep::Kind::Path: {
        if (step.path.empty()) break;
        const robot::LinearTrajectory path =
            robot::LinearTrajectory::at_speed(step.path, config.model.max_speed, step.speed_scale);
        play_trajectory(world, path, playback);
        at = step.path.back();
        break;
      }
      case robot::MotionStep::Kind::OpenGripper:
        world.set_gripper_opening(robot::FakeDriver::kGripperOpen);
        hold_for(world, playback.gripper_time, playback);
        break;
      case robot::MotionStep::Kind::CloseGripper:
        world.set_gripper_opening(0.0);
        hold_for(world, playback.gripper_time, playback);
        break;
    }
  }
}

robot::MotionPlan plan_and_play(World& world, const robot::PlannerConfig& config, const robot::Command& command,
                                const MotionPlayback& playback) {
  const robot::MotionPlan plan = robot::plan_command(config, command, targets_of(world));
  if (plan.ok()) play_motion(world, config, plan, playback);
  return plan;
}

}  // namespace nudge::sim
