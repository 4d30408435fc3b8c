// SIM_STATE to the poses the camera's sim backend renders (nudge/bus/sim_convert.hpp).
#include <gtest/gtest.h>

#include "nudge/bus/sim_convert.hpp"

namespace {

nudge::sim_state_t state_with_gripper(double gripper) {
  nudge::sim_state_t state{};
  state.utime = 1000;
  state.gripper = gripper;
  state.num_objects = 0;
  state.pusher.position[0] = 0.25;
  state.pusher.orientation[0] = 1.0;
  return state;
}

}  // namespace

// The world service's gripper field says which tool the renderer draws: -1 the pad, else the
// gripper at that opening.
TEST(BusSim, TheToolFollowsTheGripperField) {
  EXPECT_FALSE(nudge::bus::poses_of(state_with_gripper(-1.0)).gripper_opening);
  const auto gripper = nudge::bus::poses_of(state_with_gripper(0.032)).gripper_opening;
  ASSERT_TRUE(gripper);
  EXPECT_DOUBLE_EQ(*gripper, 0.032);
  EXPECT_DOUBLE_EQ(*nudge::bus::poses_of(state_with_gripper(0.0)).gripper_opening, 0.0) << "closed on nothing";
  EXPECT_NEAR(nudge::bus::poses_of(state_with_gripper(0.0)).pusher_position.x(), 0.25, 1e-12);
}
