#include "nudge/robot/driver.hpp"

#include <cmath>
#include <stdexcept>

namespace nudge::robot {

FakeDriver::FakeDriver(JointLimits limits, const JointVector& initial)
    : limits_(std::move(limits)), motion_{{0.0, initial}} {}

std::string FakeDriver::send_joint_targets(const std::vector<TimedJoints>& targets) {
  if (targets.empty()) return "no joint targets";
  double previous_time = 0;
  for (size_t i = 0; i < targets.size(); ++i) {
    const TimedJoints& target = targets[i];
    const std::string which = "target " + std::to_string(i) + ": ";
    if (!std::isfinite(target.time) || !target.q.allFinite()) return which + "not finite";
    if (!(target.time > previous_time)) return which + "time not after the previous target";
    previous_time = target.time;
    for (int j = 0; j < kNumJoints; ++j) {
      if (target.q[j] < limits_.lower[j] || target.q[j] > limits_.upper[j]) {
        return which + "joint " + std::to_string(j + 1) + " outside its limits";
      }
    }
  }
  std::vector<TimedJoints> motion{{now_, position_at(now_)}};
  for (const TimedJoints& target : targets) motion.push_back({now_ + target.time, target.q});
  motion_ = std::move(motion);
  ++accepted_commands_;
  return "";
}

JointVector FakeDriver::position_at(double time) const {
  if (time >= motion_.back().time) return motion_.back().q;
  if (time <= motion_.front().time) return motion_.front().q;
  for (size_t i = 1; i < motion_.size(); ++i) {
    if (time < motion_[i].time) {
      const TimedJoints& a = motion_[i - 1];
      const TimedJoints& b = motion_[i];
      return a.q + (time - a.time) / (b.time - a.time) * (b.q - a.q);
    }
  }
  return motion_.back().q;
}

JointState FakeDriver::read_joint_state() {
  JointState state;
  state.time = now_;
  state.position = position_at(now_);
  state.moving = now_ < motion_.back().time;
  if (state.moving) {
    for (size_t i = 1; i < motion_.size(); ++i) {
      if (now_ < motion_[i].time && now_ >= motion_[i - 1].time) {
        state.velocity =
            (motion_[i].q - motion_[i - 1].q) / (motion_[i].time - motion_[i - 1].time);
        break;
      }
    }
  }
  state.gripper_opening = gripper_opening_;
  return state;
}

void FakeDriver::stop() {
  motion_ = {{now_, position_at(now_)}};
  ++stop_count_;
}

std::string FakeDriver::open_gripper() {
  gripper_opening_ = kGripperOpen;
  return "";
}

std::string FakeDriver::close_gripper() {
  gripper_opening_ = 0.0;
  return "";
}

void FakeDriver::advance(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) {
    throw std::invalid_argument("FakeDriver::advance: seconds must be finite and non-negative");
  }
  now_ += seconds;
}

}  // namespace nudge::robot
