// arm_state_t <-> nudge::robot (nudge_bus_robot).
#include <gtest/gtest.h>

#include <cmath>

#include "nudge/bus/arm_convert.hpp"

using namespace nudge;

namespace {

bus::ArmState moving_arm() {
  bus::ArmState s;
  s.utime = 4200;
  s.joints = robot::joints_from_degrees(10, -20, 30, -40, 50, -60);
  s.gripper_opening = 0.03;
  s.tool_in_world.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  s.tool_in_world.translation() = Eigen::Vector3d(0.25, 0.05, 0.12);
  s.motion = arm_state_t::MOTION_MOVING;
  s.gripper_measured = 0.028;
  s.command_seq = 17;
  s.last_error = "none yet";
  return s;
}

std::string error_of(const arm_state_t& m) {
  try {
    bus::from_message(m);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return {};
}

}  // namespace

TEST(ArmConvert, ArmStateRoundTrips) {
  const bus::ArmState s = moving_arm();
  const arm_state_t msg = bus::to_message(s);
  EXPECT_EQ(msg.utime, 4200);
  EXPECT_DOUBLE_EQ(msg.joints[5], s.joints[5]);
  EXPECT_DOUBLE_EQ(msg.end_effector.position[0], 0.25);
  const bus::ArmState back = bus::from_message(msg);
  EXPECT_EQ(back.utime, s.utime);
  EXPECT_EQ(back.joints, s.joints);
  EXPECT_DOUBLE_EQ(back.gripper_opening, 0.03);
  EXPECT_DOUBLE_EQ(back.gripper_measured, 0.028);
  EXPECT_LT((back.tool_in_world.matrix() - s.tool_in_world.matrix()).norm(), 1e-12);
  EXPECT_EQ(back.motion + 0, arm_state_t::MOTION_MOVING + 0);
  EXPECT_EQ(back.command_seq, 17);
  EXPECT_EQ(back.last_error, "none yet");
}

TEST(ArmConvert, BadNumbersAreErrorsNamingTheField) {
  const arm_state_t good = bus::to_message(moving_arm());
  arm_state_t joint = good;
  joint.joints[3] = std::nan("");
  EXPECT_NE(error_of(joint).find("joints"), std::string::npos);
  arm_state_t gripper = good;
  gripper.gripper = INFINITY;
  EXPECT_NE(error_of(gripper).find("gripper"), std::string::npos);
  arm_state_t measured = good;
  measured.gripper_measured = std::nan("");
  EXPECT_NE(error_of(measured).find("gripper_measured"), std::string::npos);
  measured.gripper_measured = -7;  // any negative: no sensor
  EXPECT_DOUBLE_EQ(bus::from_message(measured).gripper_measured, -1.0);
  arm_state_t pose = good;
  pose.end_effector.orientation[0] = 0;
  pose.end_effector.orientation[1] = 0;
  EXPECT_NE(error_of(pose).find("end_effector"), std::string::npos);
}
