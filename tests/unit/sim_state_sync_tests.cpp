// Unit tests of nudge/sim/state_sync.hpp: the pad's yaw from the arm's tool orientation, and a
// rendering World put into a simulating World's poses (what the camera's sim backend does).
// Registered by hand in tests/CMakeLists.txt (not a tests/unit/<lib>_test.cpp of its own library).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <cmath>

#include "nudge/sim/scene.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"

namespace sim = nudge::sim;

namespace {

constexpr double kDeg = M_PI / 180.0;

sim::Scene two_objects() {
  sim::Scene scene;
  sim::ObjectSpec cup;
  cup.kind = "cup";
  cup.name = "cup";
  cup.position = {0.22, 0.08};
  sim::ObjectSpec bottle;
  bottle.kind = "bottle";
  bottle.name = "bottle";
  bottle.position = {0.28, -0.06};
  scene.objects = {cup, bottle};
  return scene;
}

}  // namespace

TEST(SimStateSync, PadYawIsTheHorizontalDirectionOfTheToolXAxis) {
  const Eigen::Quaterniond yawed(Eigen::AngleAxisd(30 * kDeg, Eigen::Vector3d::UnitZ()));
  EXPECT_NEAR(*sim::pad_yaw_from_tool(yawed), 30 * kDeg, 1e-12);
  // Tilted down by 40 deg about its own y axis: the x axis still points along 30 deg horizontally.
  const Eigen::Quaterniond tilted = yawed * Eigen::AngleAxisd(40 * kDeg, Eigen::Vector3d::UnitY());
  EXPECT_NEAR(*sim::pad_yaw_from_tool(tilted), 30 * kDeg, 1e-12);
  // Rolled about its x axis: no change either.
  const Eigen::Quaterniond rolled = yawed * Eigen::AngleAxisd(70 * kDeg, Eigen::Vector3d::UnitX());
  EXPECT_NEAR(*sim::pad_yaw_from_tool(rolled), 30 * kDeg, 1e-12);
  // The x axis straight down: no horizontal direction.
  EXPECT_FALSE(sim::pad_yaw_from_tool(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()))));
  EXPECT_FALSE(sim::pad_yaw_from_tool(Eigen::Quaterniond(std::nan(""), 0, 0, 0)));
  EXPECT_NEAR(sim::yaw_of(sim::yaw_rotation(-2.5)), -2.5, 1e-12);
}

TEST(SimStateSync, ARenderingWorldInTheSimulatedPosesDrawsTheSameImages) {
  sim::World physics(two_objects()), renderer(two_objects());
  // Move things in the simulating world: a push that slides the cup, the pad left in view.
  physics.push({0.22, 0.0, 0.02}, {0.22, 0.07, 0.02}, 0.1, 0.2);
  physics.set_object_pose(1, {0.3, -0.1, 0.0}, Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ())));
  physics.set_pusher({0.2, -0.05, 0.03}, 0.7);
  physics.step();
  const sim::PoseSnapshot poses = sim::snapshot_poses(physics, 0.7);
  ASSERT_EQ(poses.objects.size(), 2u);
  EXPECT_GT(poses.objects[0].position.y(), 0.085) << "the cup was pushed";

  sim::apply_poses(renderer, poses);
  for (int i = 0; i < 2; ++i) {
    EXPECT_LT((renderer.object(i).position - physics.object(i).position).norm(), 1e-12);
    EXPECT_LT(renderer.object(i).orientation.angularDistance(physics.object(i).orientation), 1e-9);
  }
  EXPECT_LT((renderer.pusher_position() - physics.pusher_position()).norm(), 1e-12);
  // After a step MuJoCo's body positions are those computed before its integration; restoring
  // the state recomputes them from the current poses (what the renderer was given).
  physics.set_state(physics.state());
  for (int cam = 0; cam < 2; ++cam) {
    const cv::Mat a = physics.render(cam), b = renderer.render(cam);
    EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << "camera " << cam;
  }
}

TEST(SimStateSync, AStateThatDoesNotMatchTheSceneIsRefusedAndChangesNothing) {
  sim::World world(two_objects());
  sim::PoseSnapshot poses = sim::snapshot_poses(world, 0.0);
  const Eigen::Vector3d cup_before = world.object(0).position;
  poses.objects[0].position.x() += 0.05;
  poses.objects[1].name = "teapot";
  EXPECT_THROW(sim::apply_poses(world, poses), std::invalid_argument);
  EXPECT_EQ(world.object(0).position, cup_before);
  poses.objects.pop_back();
  EXPECT_THROW(sim::apply_poses(world, poses), std::invalid_argument);
  poses = sim::snapshot_poses(world, 0.0);
  poses.pusher_yaw = std::nan("");
  EXPECT_THROW(sim::apply_poses(world, poses), std::invalid_argument);
}

TEST(SimStateSync, InterpolatedPosesForMotionBlur) {
  nudge::sim::PoseSnapshot a, b;
  a.objects.push_back({"cup", Eigen::Vector3d(0, 0, 0), Eigen::Quaterniond::Identity()});
  b.objects.push_back({"cup", Eigen::Vector3d(0.1, 0.2, 0), Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()))});
  a.pusher_yaw = 3.0;
  b.pusher_yaw = -3.0;  // the short way round crosses +-pi
  const auto half = nudge::sim::interpolate_poses(a, b, 0.5);
  EXPECT_NEAR(half.objects[0].position.x(), 0.05, 1e-12);
  EXPECT_NEAR(half.objects[0].position.y(), 0.1, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(half.objects[0].orientation).angle(), 0.5, 1e-9);
  EXPECT_NEAR(std::remainder(half.pusher_yaw - M_PI, 2 * M_PI), 0.0, 1e-9);
  const auto end = nudge::sim::interpolate_poses(a, b, 1.0);
  EXPECT_NEAR((end.objects[0].position - b.objects[0].position).norm(), 0.0, 1e-12);
  b.objects[0].name = "mug";  // different objects: nothing to interpolate
  EXPECT_EQ(nudge::sim::interpolate_poses(a, b, 0.5).objects[0].name, "mug");
}

// The camera's rendering world shows the tool the world service uses (--tool auto switches from
// the pad to the gripper at a grasp): the gripper with its fingers' opening, and the pad again.
TEST(SimStateSync, TheRenderingWorldShowsTheSimulatedTool) {
  sim::World physics(two_objects()), renderer(two_objects());
  const sim::PoseSnapshot pad = sim::snapshot_poses(physics, 0.0);
  EXPECT_FALSE(pad.gripper_opening) << "the pad is the tool at first";
  physics.set_end_effector({0.25, 0.0, 0.12}, 0.3, 0.05);
  physics.step_for(0.5);  // the fingers close from open to 5 cm
  const sim::PoseSnapshot gripper = sim::snapshot_poses(physics, 0.3);
  ASSERT_TRUE(gripper.gripper_opening);
  EXPECT_NEAR(*gripper.gripper_opening, 0.05, 0.005);

  sim::PoseSnapshot pad_there = gripper;  // the same tool point, the pad
  pad_there.gripper_opening.reset();
  sim::apply_poses(renderer, pad_there);
  EXPECT_FALSE(renderer.gripper_in_use());
  const cv::Mat with_pad = renderer.render(1);
  sim::apply_poses(renderer, gripper);
  EXPECT_TRUE(renderer.gripper_in_use());
  EXPECT_NEAR(renderer.gripper_opening(), *gripper.gripper_opening, 1e-9) << "the fingers drawn where they are";
  EXPECT_LT((renderer.pusher_position() - physics.pusher_position()).norm(), 1e-12);
  const cv::Mat with_gripper = renderer.render(1);
  EXPECT_GT(cv::norm(with_pad, with_gripper, cv::NORM_L1), 0.0) << "the gripper is drawn, not the pad";

  sim::apply_poses(renderer, pad_there);
  EXPECT_FALSE(renderer.gripper_in_use()) << "the pad again";

  sim::PoseSnapshot back = gripper;
  back.gripper_opening = std::nan("");
  EXPECT_THROW(sim::apply_poses(renderer, back), std::invalid_argument);
  EXPECT_FALSE(renderer.gripper_in_use()) << "a bad state changes nothing";

  // Motion blur between two gripper states interpolates the opening; pad to gripper takes the later.
  sim::PoseSnapshot wide = gripper;
  wide.gripper_opening = 0.09;
  EXPECT_NEAR(*sim::interpolate_poses(gripper, wide, 0.5).gripper_opening, 0.5 * (*gripper.gripper_opening + 0.09), 1e-12);
  EXPECT_EQ(sim::interpolate_poses(pad, wide, 0.5).gripper_opening, wide.gripper_opening);
}
