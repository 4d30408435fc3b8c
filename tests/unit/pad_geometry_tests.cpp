// The pad the planners assume is the pad the simulated world pushes with. The supervisor keeps
// other objects' axes TargetParams::object_radius from the rectangle the pad sweeps,
// pad_half_width either side of the push line, and the robot library puts the pad's face
// NudgeParams::pad_front ahead of the tool point; the world's pad is a box of
// sim::pusher_pad_half_size() (x: along the push, y: across it). The supervisor once assumed a pad
// half as wide as the world's, and let it pass within 3 cm of a neighbour's axis.
#include <gtest/gtest.h>

#include "nudge/robot/motions.hpp"
#include "nudge/sim/mjcf.hpp"
#include "nudge/supervisor/targets.hpp"

TEST(PadGeometry, TheSupervisorsPadIsAsWideAsTheSimulatedOne) {
  EXPECT_DOUBLE_EQ(nudge::supervisor::TargetParams{}.pad_half_width, nudge::sim::pusher_pad_half_size().y());
}

TEST(PadGeometry, TheRobotsPadFaceIsTheSimulatedPadsFace) {
  EXPECT_DOUBLE_EQ(nudge::robot::NudgeParams{}.pad_front, nudge::sim::pusher_pad_half_size().x());
}
