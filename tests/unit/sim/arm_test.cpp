// The PUMA 260 in the world: kinematics, servos, sweeps, nudges, the table as a stop.
#include "sim_test_helpers.hpp"

#include <array>
#include <random>

#include "nudge/robot/command_planner.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/sim/arm_motion.hpp"

using namespace nudge::sim;
using namespace nudge::sim::test;

// ---------------------------------------------------------------- the PUMA 260 in the world

namespace {

Scene with_arm(Scene scene) {
  scene.arm.present = true;
  return scene;
}

std::array<double, 6> degrees(double j1, double j2, double j3, double j4, double j5, double j6) {
  return {j1 * kDeg, j2 * kDeg, j3 * kDeg, j4 * kDeg, j5 * kDeg, j6 * kDeg};
}

nudge::robot::JointVector as_joint_vector(const std::array<double, 6>& q) {
  return Eigen::Map<const nudge::robot::JointVector>(q.data());
}

}  // namespace

TEST(SimArm, LinksFollowTheRobotLibrarysKinematics) {
  // The MuJoCo bodies built from Table B.1 put the flange exactly where the robot library's
  // forward kinematics (eq. B.1-B.2) does, lifted to the shoulder.
  const Scene scene = with_arm(default_scene());
  World world(scene);
  ASSERT_TRUE(world.has_arm());
  const nudge::robot::ArmModel puma = nudge::robot::puma260();
  std::mt19937 rng(4);
  for (int trial = 0; trial < 200; ++trial) {
    std::array<double, 6> q;
    for (int j = 0; j < 6; ++j) q[j] = std::uniform_real_distribution<double>(puma.limits.lower[j], puma.limits.upper[j])(rng);
    world.set_arm_joints(q);
    Eigen::Isometry3d expected = nudge::robot::flange_pose(puma, as_joint_vector(q));
    expected.translation().z() += scene.arm.shoulder_height;
    const Eigen::Isometry3d simulated = world.arm_flange_pose();
    ASSERT_LT((simulated.translation() - expected.translation()).norm(), 1e-9) << "trial " << trial;
    ASSERT_LT((simulated.linear() - expected.linear()).norm(), 1e-9) << "trial " << trial;
    for (int j = 0; j < 6; ++j) ASSERT_DOUBLE_EQ(world.arm_joints()[j], q[j]);
  }
}

TEST(SimArm, ServosBringTheArmToItsTargetsAgainstGravity) {
  World world(with_arm(default_scene()));
  const std::array<double, 6> start = world.arm_joints();
  // The arm leaning out over the table: gravity pulls hardest on the shoulder and elbow here.
  const std::array<double, 6> target = degrees(20, -10, -100, 30, 60, -45);
  world.set_arm_targets(target);
  world.step_for(0.02);
  double moved = 0, left = 0;
  for (int j = 0; j < 6; ++j) {
    moved = std::max(moved, std::fabs(world.arm_joints()[j] - start[j]));
    left = std::max(left, std::fabs(world.arm_joints()[j] - target[j]));
  }
  EXPECT_GT(moved, 0.1 * kDeg) << "the servos move the joints";
  EXPECT_GT(left, 5 * kDeg) << "with their dynamics: not there after 20 ms";
  world.step_for(2.0);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(world.arm_joints()[j], target[j], 0.05 * kDeg) << "joint " << j + 1;
  // Held there: a second later it has not drooped.
  world.step_for(1.0);
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(world.arm_joints()[j], target[j], 0.05 * kDeg) << "joint " << j + 1;
  // Targets beyond a joint's limits are clamped to them.
  world.set_arm_targets(degrees(0, 0, -90, 0, 150, 0));
  EXPECT_NEAR(world.arm_targets()[4], nudge::robot::puma260().limits.upper[4], 1e-8);
  EXPECT_THROW(world.set_arm_targets(degrees(0, std::nan(""), 0, 0, 0, 0)), std::invalid_argument);
  World armless(default_scene());
  EXPECT_FALSE(armless.has_arm());
  EXPECT_THROW(armless.set_arm_targets(target), SimError);
}

TEST(SimArm, TheForearmSweepsACupAside) {
  // The upper arm tilted down and the forearm hanging: turning joint 1 swings the wrist through
  // a cup standing on its circle.
  Scene scene = with_arm(one_object("cup", 0.3, 0.0));
  scene.arm.joints = degrees(-50, -20, -180, 0, 0, 0);
  World probe(scene);
  probe.set_arm_joints(degrees(0, -20, -180, 0, 0, 0));
  const Eigen::Vector3d wrist = probe.arm_flange_pose().translation();
  ASSERT_LT(wrist.z(), 0.08) << "the wrist hangs low enough to meet a cup";
  scene.objects[0].position = wrist.head<2>();
  World world(scene);
  const Eigen::Vector3d before = world.object(0).position;
  world.step_for(0.5);
  EXPECT_LT((world.object(0).position - before).norm(), 1e-3) << "untouched while the arm is away";
  world.set_arm_targets(degrees(50, -20, -180, 0, 0, 0));
  world.step_for(3.0);
  const ObjectState after = world.object(0);
  EXPECT_GT((after.position - before).norm() + 0.1 * after.tilt(), 0.02) << "moved or knocked over";
}

TEST(SimArm, ReplaysExactlyAndIsDrawn) {
  World world(with_arm(load_scene(scene_path("three_objects.yaml"))));
  world.set_arm_targets(degrees(10, 30, -120, 0, 45, 0));
  world.step(100);
  const std::vector<double> saved = world.state();
  auto run = [&world]() {
    for (int k = 0; k < 200; ++k) {
      world.set_arm_targets(degrees(10 + 0.05 * k, 30, -120, 0, 45, 0));
      world.step();
    }
    return world.state();
  };
  const std::vector<double> first = run();
  world.set_state(saved);
  EXPECT_EQ(first, run());
  // The arm stands in front of the cameras: the pictures with it differ from those without.
  World armless(load_scene(scene_path("three_objects.yaml")));
  cv::Mat with = world.render(1), without = armless.render(1), diff;
  cv::absdiff(with, without, diff);
  cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(diff > 30), 2000) << "the arm is in the right camera's view";
  // It is not an object: masks gain no pixels from it (a few on object outlines may differ: the
  // objects settled in two different models).
  cv::Mat mask_diff;
  const cv::Mat armless_objects = armless.render_mask(1) > 0;
  cv::compare(world.render_mask(1) > 0, armless_objects, mask_diff, cv::CMP_GT);
  EXPECT_LT(cv::countNonZero(mask_diff), 0.002 * cv::countNonZero(armless_objects));
}

TEST(SimArm, ToolsRideOnTheFlange) {
  World world(with_arm(default_scene()));
  EXPECT_FALSE(world.tools_on_arm());
  world.mount_tools_on_arm(0.15);
  EXPECT_TRUE(world.tools_on_arm());
  world.set_arm_targets(degrees(15, 40, -150, 0, 20, 30));
  world.step_for(2.0);
  const Eigen::Isometry3d flange = world.arm_flange_pose();
  const Eigen::Vector3d tool = flange.translation() + 0.15 * flange.linear().col(2);
  EXPECT_LT((world.pusher_position() - tool).norm(), 1e-4) << "the pad is at the arm's tool point";
  // The gripper, picked by its opening, is there too and closes.
  world.set_gripper_opening(0.02);
  EXPECT_TRUE(world.gripper_in_use());
  world.step_for(0.5);
  EXPECT_NEAR(world.gripper_opening(), 0.02, 2e-3);
  EXPECT_LT((world.pusher_position() - tool).norm(), 1e-4);
  World armless(default_scene());
  EXPECT_THROW(armless.mount_tools_on_arm(), SimError);
}

// Plays a nudge planned by the robot library on the simulated arm's servos, the pad mounted on
// its flange (home first, then the path at no more than 0.5 deg per 10 ms), and lets the object
// settle; returns it.
static ObjectState play_planned_nudge(const Scene& scene, const Eigen::Vector2d& target, const Eigen::Vector2d& direction,
                               const nudge::robot::NudgeParams& params, Eigen::Vector3d* before) {
  namespace robot = nudge::robot;
  World world(scene);
  world.mount_tools_on_arm(0.15);
  const robot::ArmModel puma = robot::puma260();
  robot::SafetyConfig safety;
  safety.table_z = -scene.arm.shoulder_height;
  const robot::IkResult home = robot::home_configuration(puma, safety);
  EXPECT_TRUE(home.ok()) << home.reason;
  const robot::NudgePlan plan = robot::plan_nudge(puma, safety, Eigen::Vector3d(target.x(), target.y(), safety.table_z),
                                                  Eigen::Vector3d(direction.x(), direction.y(), 0), params, home.q);
  EXPECT_TRUE(plan.ok()) << plan.reason;
  auto as_array = [](const robot::JointVector& q) {
    std::array<double, 6> a;
    for (int j = 0; j < 6; ++j) a[j] = q[j];
    return a;
  };
  world.set_arm_joints(as_array(home.q));
  world.step_for(0.5);
  *before = world.object(0).position;
  robot::JointVector at = home.q;
  for (const robot::JointVector& next : plan.waypoints) {
    const int steps = std::max(1, static_cast<int>(std::ceil((next - at).cwiseAbs().maxCoeff() / (0.5 * kDeg))));
    for (int k = 1; k <= steps; ++k) {
      world.set_arm_targets(as_array(at + (next - at) * (static_cast<double>(k) / steps)));
      world.step(5);
    }
    at = next;
  }
  world.step_for(1.5);
  return world.object(0);
}

TEST(SimArm, TheSimulatedArmNudgesACupAcrossTheTable) {
  // The thesis' nudge (fig. 6.3-6.4): the cup slides a few centimetres, upright.
  Eigen::Vector3d before;
  const ObjectState after = play_planned_nudge(with_arm(one_object("cup", 0.25, 0.0)), {0.25, 0.0}, {0, 1},
                                               nudge::robot::NudgeParams{}, &before);
  const double moved = (after.position - before).head<2>().norm();
  EXPECT_GT(moved, 0.01) << "the cup moved 1-3 cm";
  EXPECT_LT(moved, 0.03) << "the cup moved 1-3 cm";
  EXPECT_GT(after.position.y() - before.y(), 0.004) << "along the push direction";
  EXPECT_LT(after.tilt(), 5 * kDeg) << "and stayed upright";
}

TEST(SimArm, TheNudgeKeepsTheWristOffATallBottle) {
  // A 200 mm bottle pushed across the table: with the tool straight down (the thesis' tool) the
  // wrist rides 150 mm above the pad, beside the bottle's shoulder, and knocks it over; the
  // planner leans the tool so that the wrist trails the pad, and the bottle slides, upright.
  const Scene scene = with_arm(one_object("bottle", 0.26, 0.045));
  const Eigen::Vector2d target(0.26, 0.045), direction(0.14, -0.99);
  Eigen::Vector3d before;
  const ObjectState leaned = play_planned_nudge(scene, target, direction.normalized(), nudge::robot::NudgeParams{}, &before);
  EXPECT_GT((leaned.position - before).head<2>().norm(), 0.01) << "the bottle moved";
  EXPECT_LT(leaned.tilt(), 5 * kDeg) << "and stayed upright";
  nudge::robot::NudgeParams straight_down;
  straight_down.object_height = 0;  // no clearance check: the tool points straight down
  // Pushing 10 mm up puts the wrist at 160 mm, at the shoulder (the default's 180 mm passes by the
  // narrow neck of this bottle; a taller object meets it there).
  straight_down.push_height = 0.010;
  const ObjectState struck = play_planned_nudge(scene, target, direction.normalized(), straight_down, &before);
  EXPECT_GT(struck.tilt(), 30 * kDeg) << "the straight-down tool's wrist knocks the bottle over";
}

// The arm service's own plans (robot::plan_command, the default workspace) played on the servos:
// home from the scene's start, then a nudge with the given push height. Returns the object's
// largest tilt during the nudge and where it settled.
struct PlayedNudge {
  double max_tilt = 0;
  ObjectState before, after;
};
static PlayedNudge play_service_nudge(const Scene& scene, const Eigen::Vector2d& target, const Eigen::Vector2d& direction,
                                      double push_height) {
  namespace robot = nudge::robot;
  const robot::PlannerConfig config = robot::planner_config(robot::Workspace{});
  World world(scene);
  world.mount_tools_on_arm(config.model.tool.translation().norm());
  robot::Command home;
  home.kind = robot::CommandKind::Home;
  EXPECT_TRUE(plan_and_play(world, config, home).ok());
  world.step_for(0.3);
  PlayedNudge played;
  played.before = world.object(0);
  robot::Command nudge;
  nudge.kind = robot::CommandKind::Nudge;
  nudge.target_position = Eigen::Vector3d(target.x(), target.y(), 0);
  nudge.direction = Eigen::Vector3d(direction.x(), direction.y(), 0);
  nudge.height = push_height;
  MotionPlayback playback;
  playback.each_period = [&played](const World& w) { played.max_tilt = std::max(played.max_tilt, w.object(0).tilt()); };
  const robot::MotionPlan plan = plan_and_play(world, config, nudge, playback);
  EXPECT_TRUE(plan.ok()) << plan.reason;
  world.step_for(1.5);
  played.after = world.object(0);
  return played;
}

TEST(SimArm, TheDefaultPushHeightSlidesAnEmptyBottleThatALowPushLaysDown) {
  // The learning experiment's half-transparent bottle (empty), pushed where its survey put it: at
  // the old 10 mm push height the pad laid it down; at the default it slides, upright.
  Scene scene = with_arm(one_object("bottle", 0.2682, 0.03364));
  scene.objects[0].yaw = 321.7 * kDeg;
  const Eigen::Vector2d target(0.2695, 0.0341), direction(0.153, -0.988);
  const PlayedNudge low = play_service_nudge(scene, target, direction.normalized(), 0.010);
  EXPECT_GT(low.after.tilt(), 30 * kDeg) << "a 10 mm push lays the bottle down";
  const PlayedNudge standard = play_service_nudge(scene, target, direction.normalized(), 0);  // 0: the default
  EXPECT_LT(standard.max_tilt, 5 * kDeg) << "the default push height keeps it upright";
  const double moved = (standard.after.position - standard.before.position).head<2>().norm();
  EXPECT_GT(moved, 0.01) << "and slides it the thesis' 1-3 cm";
  EXPECT_LT(moved, 0.03);
}

TEST(SimArm, PlayingAMotionRefusesARefusedPlanAndAWorldWithoutAnArm) {
  namespace robot = nudge::robot;
  const robot::PlannerConfig config = robot::planner_config(robot::Workspace{});
  World world(with_arm(default_scene()));
  robot::MotionPlan refused;
  refused.reason = "nudge target: outside the ring";
  EXPECT_THROW(play_motion(world, config, refused), std::invalid_argument);
  MotionPlayback no_time;
  no_time.period = 0;
  EXPECT_THROW(play_motion(world, config, robot::MotionPlan{}, no_time), std::invalid_argument);
  World armless(default_scene());
  EXPECT_THROW(play_motion(armless, config, robot::MotionPlan{}), SimError);
  // A command the arm would refuse (a nudge outside the workspace ring) moves nothing.
  robot::Command too_far;
  too_far.kind = robot::CommandKind::Nudge;
  too_far.target_position = Eigen::Vector3d(0.6, 0.0, 0);
  too_far.direction = Eigen::Vector3d(0, 1, 0);
  const std::array<double, 6> before = world.arm_targets();
  const robot::MotionPlan plan = plan_and_play(world, config, too_far);
  EXPECT_FALSE(plan.ok());
  EXPECT_NE(plan.reason.find("ring"), std::string::npos) << plan.reason;
  EXPECT_EQ(world.arm_targets(), before);
}

TEST(SimArm, TheTableStopsALinkCommandedThroughIt) {
  // Upper arm 45 deg down, forearm straight down: by the robot library's kinematics the wrist
  // would be under the table top; the simulated forearm comes to rest on the table instead.
  const Scene scene = with_arm(default_scene());
  const std::array<double, 6> below = degrees(0, -45, -135, 0, 0, 0);
  const nudge::robot::ArmPoints p = nudge::robot::arm_points(nudge::robot::puma260(), as_joint_vector(below));
  ASSERT_LT(p.wrist.z() + scene.arm.shoulder_height, 0.0);
  World world(scene);
  world.set_arm_targets(below);
  world.step_for(2.0);
  EXPECT_GT(world.arm_flange_pose().translation().z(), 0.01) << "the wrist stays above the table top";
  EXPECT_GT(std::fabs(world.arm_joints()[1] - below[1]) + std::fabs(world.arm_joints()[2] - below[2]), 1 * kDeg)
      << "so the joints cannot reach their targets";
}
