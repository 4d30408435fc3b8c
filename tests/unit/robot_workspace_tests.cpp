// The workspace file and its flags, the command planner the arm service (and the supervisor to
// come) runs every command through, and the simulated arm driver (nudge_robot).
#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "nudge/robot/command_planner.hpp"
#include "nudge/robot/driver.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/workspace.hpp"
#include "nudge/robot/workspace_flags.hpp"

using namespace nudge::robot;

namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// A file in the test's temporary directory with `text` as its content.
std::string write_file(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/" + name + "_" + std::to_string(::getpid()) + ".yaml";
  std::ofstream(path) << text;
  return path;
}

const char* const kGoodWorkspace =
    "%YAML:1.0\n---\n"
    "base_yaw_deg: 90\n"
    "shoulder_height: 0.35\n"
    "tool_length: 0.12\n"
    "ring_inner: 0.16\n"
    "ring_outer: 0.34\n"
    "table_margin: 0.01\n";

// The message load_workspace throws for `text`, or "" when it loads.
std::string load_error(const std::string& name, const std::string& text) {
  const std::string path = write_file(name, text);
  try {
    load_workspace(path);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// Runs Flags::parse on `args` (after the program name).
void parse(nudge::Flags& flags, std::vector<std::string> args) {
  args.insert(args.begin(), "test");
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  flags.parse(static_cast<int>(argv.size()), argv.data());
}

JointVector home_joints(const PlannerConfig& config) {
  SafetyConfig safety = config.safety;
  safety.table_z = config.base.table_z();
  const IkResult home = home_configuration(config.model, safety, config.home_radius, config.home_height);
  EXPECT_TRUE(home.ok()) << home.reason;
  return home.q;
}

Command nudge_at(const Eigen::Vector3d& target, const Eigen::Vector3d& direction) {
  Command c;
  c.kind = CommandKind::Nudge;
  c.target_position = target;
  c.direction = direction;
  return c;
}

// The tool point (world frame) at the end of every step of a plan, executed from `current`.
std::vector<Eigen::Vector3d> step_ends(const PlannerConfig& config, const MotionPlan& plan) {
  std::vector<Eigen::Vector3d> ends;
  for (const MotionStep& step : plan.steps) {
    if (step.kind == MotionStep::Kind::Move) {
      ends.push_back(config.base.to_world(forward_kinematics(config.model, step.goal)).translation());
    } else if (step.kind == MotionStep::Kind::Path) {
      ends.push_back(config.base.to_world(forward_kinematics(config.model, step.path.back())).translation());
    }
  }
  return ends;
}

}  // namespace

// ---------------------------------------------------------------- the workspace file

TEST(WorkspaceFile, GoodFileIsReadWithTheYawInDegrees) {
  const Workspace w = load_workspace(write_file("good", kGoodWorkspace));
  EXPECT_NEAR(w.base_yaw, M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(w.shoulder_height, 0.35);
  EXPECT_DOUBLE_EQ(w.tool_length, 0.12);
  EXPECT_DOUBLE_EQ(w.ring_inner, 0.16);
  EXPECT_DOUBLE_EQ(w.ring_outer, 0.34);
  EXPECT_DOUBLE_EQ(w.table_margin, 0.01);
}

TEST(WorkspaceFile, TheDefaultFileHoldsTheDefaultsInCode) {
  const Workspace file = load_workspace(std::string(NUDGE_SOURCE_DIR) + "/config/workspace.yaml");
  const Workspace code;
  EXPECT_DOUBLE_EQ(file.base_yaw, code.base_yaw);
  EXPECT_DOUBLE_EQ(file.shoulder_height, code.shoulder_height);
  EXPECT_DOUBLE_EQ(file.tool_length, code.tool_length);
  EXPECT_DOUBLE_EQ(file.ring_inner, code.ring_inner);
  EXPECT_DOUBLE_EQ(file.ring_outer, code.ring_outer);
  EXPECT_DOUBLE_EQ(file.table_margin, code.table_margin);
}

TEST(WorkspaceFile, MissingFieldIsNamedWithTheFile) {
  const std::string error = load_error("missing", replace(kGoodWorkspace, "tool_length: 0.12\n", ""));
  EXPECT_TRUE(contains(error, "missing_")) << error;  // the file
  EXPECT_TRUE(contains(error, "tool_length: missing")) << error;
}

TEST(WorkspaceFile, BadValuesAreNamedWithTheFile) {
  std::string error = load_error("text", replace(kGoodWorkspace, "ring_outer: 0.34", "ring_outer: wide"));
  EXPECT_TRUE(contains(error, "text_")) << error;
  EXPECT_TRUE(contains(error, "ring_outer: expected a number")) << error;
  error = load_error("crossed", replace(kGoodWorkspace, "ring_outer: 0.34", "ring_outer: 0.1"));
  EXPECT_TRUE(contains(error, "crossed_")) << error;
  EXPECT_TRUE(contains(error, "ring_outer: ring_outer must be finite and larger than ring_inner")) << error;
  error = load_error("negative", replace(kGoodWorkspace, "shoulder_height: 0.35", "shoulder_height: -0.3"));
  EXPECT_TRUE(contains(error, "shoulder_height: shoulder_height must be positive")) << error;
  error = load_error("typo", std::string(kGoodWorkspace) + "ring_outter: 0.3\n");
  EXPECT_TRUE(contains(error, "ring_outter: unknown field")) << error;
  error = load_error("list", replace(kGoodWorkspace, "tool_length: 0.12", "tool_length: [0.1, 0.2]"));
  EXPECT_TRUE(contains(error, "tool_length: expected a number")) << error;
}

TEST(WorkspaceFile, UnreadableFileIsNamed) {
  try {
    load_workspace("/no/such/workspace.yaml");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_TRUE(contains(e.what(), "/no/such/workspace.yaml: cannot read")) << e.what();
  }
  const std::string error = load_error("garbage", "this: [is not: yaml");
  EXPECT_TRUE(contains(error, "garbage_")) << error;
}

// OpenCV's cv::FileStorage, which read this file before, looped for ever on the first (found by
// fuzz_workspace): a service given it hung at start-up. Every malformed file is now refused.
TEST(WorkspaceFile, MalformedYamlIsRefusedNamingTheFileNotLoopedOn) {
  std::string error = load_error("hang", "%YAML:1.0\n---a%YAML:1.0\n-#e \n --\nr flagstool_l#en The a");
  EXPECT_TRUE(contains(error, "hang_")) << error;
  EXPECT_TRUE(contains(error, "(top level): expected a map of workspace fields")) << error;
  error = load_error("flow", replace(kGoodWorkspace, "tool_length: 0.12", "tool_length: [0.12]]"));
  EXPECT_TRUE(contains(error, "flow_")) << error;
  EXPECT_TRUE(contains(error, "not a valid workspace file: line")) << error;
  error = load_error("quoted", replace(kGoodWorkspace, "tool_length: 0.12", "tool_length: '0.12'"));
  EXPECT_TRUE(contains(error, "tool_length: expected a number")) << error;
  error = load_error("empty", "");
  EXPECT_TRUE(contains(error, "(top level): expected a map")) << error;
  error = load_error("alias", std::string(kGoodWorkspace) + "loop: &a [*a]\n");
  EXPECT_TRUE(contains(error, "loop: unknown field")) << error;
}

TEST(WorkspaceFile, SavedFileLoadsTheSame) {
  Workspace w;
  w.base_yaw = 0.3;
  w.shoulder_height = 0.31;
  w.tool_length = 0.1;
  w.ring_inner = 0.12;
  w.ring_outer = 0.3;
  w.table_margin = 0.002;
  const std::string path = ::testing::TempDir() + "/saved_" + std::to_string(::getpid()) + ".yaml";
  save_workspace(w, path);
  const Workspace back = load_workspace(path);
  EXPECT_NEAR(back.base_yaw, w.base_yaw, 1e-12);
  EXPECT_DOUBLE_EQ(back.shoulder_height, w.shoulder_height);
  EXPECT_DOUBLE_EQ(back.tool_length, w.tool_length);
  EXPECT_DOUBLE_EQ(back.ring_inner, w.ring_inner);
  EXPECT_DOUBLE_EQ(back.ring_outer, w.ring_outer);
  EXPECT_DOUBLE_EQ(back.table_margin, w.table_margin);
}

TEST(Workspace, AppliesToTheModelTheSafetyChecksAndTheBase) {
  const Workspace w = load_workspace(write_file("apply", kGoodWorkspace));
  ArmModel model = puma260();
  SafetyConfig safety;
  apply_workspace(w, &model);
  apply_workspace(w, &safety);
  EXPECT_DOUBLE_EQ(model.tool.translation().z(), 0.12);
  EXPECT_DOUBLE_EQ(safety.table_z, -0.35);
  EXPECT_DOUBLE_EQ(safety.ring_inner, 0.16);
  EXPECT_DOUBLE_EQ(safety.ring_outer, 0.34);
  EXPECT_DOUBLE_EQ(safety.table_margin, 0.01);
  // The base turned by 90 degrees: its x axis is the world's y axis, its origin at the shoulder.
  const BaseFrame base = BaseFrame::of(w);
  EXPECT_LT((base.point_to_base({0.0, 0.25, 0.35}) - Eigen::Vector3d(0.25, 0.0, 0.0)).norm(), 1e-12);
  EXPECT_LT((base.direction_to_base({0.0, 1.0, 0.0}) - Eigen::Vector3d(1.0, 0.0, 0.0)).norm(), 1e-12);
  EXPECT_DOUBLE_EQ(base.table_z(), -0.35);
}

// ---------------------------------------------------------------- --workspace and its overrides

TEST(WorkspaceFlags, DefaultsThenTheFileThenTheFlagsGiven) {
  {
    nudge::Flags flags("test", "");
    const WorkspaceFlags workspace(flags, {"ring-inner", "tool-length"});
    parse(flags, {});
    const Workspace w = workspace.resolve();
    EXPECT_DOUBLE_EQ(w.ring_inner, Workspace{}.ring_inner);
    EXPECT_DOUBLE_EQ(w.tool_length, Workspace{}.tool_length);
  }
  {
    nudge::Flags flags("test", "");
    const WorkspaceFlags workspace(flags, {"ring-inner", "tool-length"});
    parse(flags, {"--workspace", write_file("flags", kGoodWorkspace), "--ring-inner", "0.2"});
    const Workspace w = workspace.resolve();
    EXPECT_DOUBLE_EQ(w.ring_inner, 0.2);     // the flag given
    EXPECT_DOUBLE_EQ(w.tool_length, 0.12);   // the file's, not the flag's default
    EXPECT_DOUBLE_EQ(w.ring_outer, 0.34);
  }
}

TEST(WorkspaceFlags, BadFilesAndOverridesAreFlagErrors) {
  {
    nudge::Flags flags("test", "");
    const WorkspaceFlags workspace(flags, {"ring-inner", "ring-outer"});
    parse(flags, {"--ring-inner", "0.4", "--ring-outer", "0.3"});
    EXPECT_THROW(workspace.resolve(), nudge::FlagError);
  }
  {
    nudge::Flags flags("test", "");
    const WorkspaceFlags workspace(flags, {});
    parse(flags, {"--workspace", write_file("bad_flags", replace(kGoodWorkspace, "table_margin: 0.01\n", ""))});
    try {
      workspace.resolve();
      FAIL() << "no error";
    } catch (const nudge::FlagError& e) {
      EXPECT_TRUE(contains(e.what(), "--workspace")) << e.what();
      EXPECT_TRUE(contains(e.what(), "table_margin: missing")) << e.what();
    }
  }
  nudge::Flags flags("test", "");
  EXPECT_THROW(WorkspaceFlags(flags, {"no-such-field"}), std::invalid_argument);
}

// ---------------------------------------------------------------- the command planner

TEST(PlanCommand, ReachableNudgeIsPlannedAndChecked) {
  const PlannerConfig config = planner_config(Workspace{});
  const JointVector home = home_joints(config);
  const Eigen::Vector3d target(0.25, 0.0, 0.0), direction(0.0, 1.0, 0.0);
  const MotionPlan plan = plan_command(config, nudge_at(target, direction), home);
  ASSERT_TRUE(plan.ok()) << plan.reason;
  EXPECT_FALSE(plan.malformed);
  ASSERT_EQ(plan.steps.size(), 2u);
  EXPECT_EQ(plan.steps[0].kind, MotionStep::Kind::Move);
  EXPECT_EQ(plan.steps[1].kind, MotionStep::Kind::Path);
  EXPECT_DOUBLE_EQ(plan.steps[0].speed_scale, config.speed_scale);
  // P0 above the start point, Dmax before the axis; the path comes back to it.
  const std::vector<Eigen::Vector3d> ends = step_ends(config, plan);
  const Eigen::Vector3d p0 = target - config.nudge.start_distance * direction +
                             Eigen::Vector3d(0, 0, config.nudge.approach_height);
  EXPECT_LT((ends[0] - p0).norm(), 1e-6);
  EXPECT_LT((ends[1] - p0).norm(), 1e-6);
  // The tool never passes Dmin before the axis.
  for (const JointVector& q : plan.steps[1].path) {
    const Eigen::Vector3d tool = config.base.to_world(forward_kinematics(config.model, q)).translation();
    EXPECT_LE((tool - target).dot(direction), -config.nudge.stop_distance + 1e-9);
  }
  SafetyConfig safety = config.safety;
  safety.table_z = config.base.table_z();
  EXPECT_EQ(check_steps(config.model, safety, plan.steps, home), "");
}

// A leaned tool can put P0 in another arm configuration (a left arm, where the right arm's joint 5
// would pass its limit by 0.2 deg); the straight joint line from home to it swings the tool out of
// the workspace ring, and the arm would refuse the nudge. Another lean is planned instead.
TEST(PlanCommand, NudgesAcrossTheRingStartWhereTheArmCanSwingTo) {
  const PlannerConfig config = planner_config(Workspace{});
  const JointVector home = home_joints(config);
  const MotionPlan swung = plan_command(config, nudge_at({0.0, -0.27, 0.0}, {-1.0, 0.0, 0.0}), home);
  EXPECT_TRUE(swung.ok()) << swung.reason;
  int refused_at_p0 = 0, planned = 0;
  for (double radius : {0.20, 0.25, 0.30})
    for (double bearing_deg = -90; bearing_deg <= 90; bearing_deg += 30) {
      const double b = bearing_deg * M_PI / 180;
      for (double way : {1.0, -1.0}) {
        const MotionPlan plan = plan_command(
            config, nudge_at({radius * std::cos(b), radius * std::sin(b), 0.0}, {-way * std::sin(b), way * std::cos(b), 0.0}), home);
        planned += plan.ok();
        refused_at_p0 += contains(plan.reason, "the move to P0");
      }
    }
  EXPECT_EQ(refused_at_p0, 0);  // 6 of these 42 before, when 36 planned
  EXPECT_GE(planned, 40);
}

TEST(PlanCommand, NudgeIsPlannedInTheWorldFrameOfATurnedBase) {
  Workspace turned;
  turned.base_yaw = M_PI / 2;  // base x along world y
  const PlannerConfig config = planner_config(turned);
  const Eigen::Vector3d target(0.0, 0.25, 0.0), direction(-1.0, 0.0, 0.0);
  const MotionPlan plan = plan_command(config, nudge_at(target, direction), home_joints(config));
  ASSERT_TRUE(plan.ok()) << plan.reason;
  const Eigen::Vector3d p0 = target - config.nudge.start_distance * direction +
                             Eigen::Vector3d(0, 0, config.nudge.approach_height);
  EXPECT_LT((step_ends(config, plan)[0] - p0).norm(), 1e-6);
}

TEST(PlanCommand, OutOfRingNudgeIsRefusedWithItsReason) {
  const PlannerConfig config = planner_config(Workspace{});
  const MotionPlan plan = plan_command(config, nudge_at({0.45, 0.0, 0.0}, {0.0, 1.0, 0.0}), home_joints(config));
  EXPECT_FALSE(plan.ok());
  EXPECT_FALSE(plan.malformed);
  EXPECT_TRUE(plan.steps.empty());
  EXPECT_TRUE(contains(plan.reason, "workspace ring")) << plan.reason;
  // A wider ring from the workspace lets the planner try it (and it fails only for reach or not at all).
  Workspace wide;
  wide.ring_outer = 0.5;
  const PlannerConfig wider = planner_config(wide);
  const MotionPlan again = plan_command(wider, nudge_at({0.45, 0.0, 0.0}, {0.0, 1.0, 0.0}), home_joints(wider));
  EXPECT_FALSE(contains(again.reason, "workspace ring")) << again.reason;
}

TEST(PlanCommand, ANudgeClearsTheObjectHeightItIsGivenOrTheTallestExpected) {
  PlannerConfig config = planner_config(Workspace{});
  config.nudge.tool_tilt = 0;  // the thesis' straight-down tool: its wrist rides beside the object
  const JointVector home = home_joints(config);
  Command tall = nudge_at({0.26, 0.045, 0.0}, {0.0, -1.0, 0.0});
  const MotionPlan refused = plan_command(config, tall, home);
  EXPECT_FALSE(refused.ok());
  EXPECT_FALSE(refused.malformed);
  EXPECT_TRUE(contains(refused.reason, "forearm or wrist")) << refused.reason;
  Command cup = tall;
  cup.object_height = 0.08;  // measured: the wrist passes above it
  EXPECT_TRUE(plan_command(config, cup, home).ok());
  Command negative = tall;
  negative.object_height = -0.1;
  const MotionPlan bad = plan_command(config, negative, home);
  EXPECT_TRUE(bad.malformed);
}

TEST(PlanCommand, MalformedCommandsAreRefusedAsMalformed) {
  const PlannerConfig config = planner_config(Workspace{});
  const JointVector home = home_joints(config);
  Command fast = nudge_at({0.25, 0.0, 0.0}, {0.0, 1.0, 0.0});
  fast.speed_scale = 2.0;
  MotionPlan plan = plan_command(config, fast, home);
  EXPECT_TRUE(plan.malformed);
  EXPECT_TRUE(contains(plan.reason, "speed_scale 2")) << plan.reason;

  Command five;
  five.kind = CommandKind::MoveJoints;
  five.joints = {0, 0, 0, 0, 0};
  plan = plan_command(config, five, home);
  EXPECT_TRUE(plan.malformed);
  EXPECT_EQ(plan.reason, "needs 6 joints, got 5");

  Command pose;
  pose.kind = CommandKind::MovePose;
  pose.target_position = {0.25, 0.0, 0.2};
  pose.target_orientation = {2.0, 0.0, 0.0, 0.0};  // not a unit quaternion
  plan = plan_command(config, pose, home);
  EXPECT_TRUE(plan.malformed);

  Command nan_nudge = nudge_at({std::nan(""), 0.0, 0.0}, {0.0, 1.0, 0.0});
  plan = plan_command(config, nan_nudge, home);
  EXPECT_TRUE(plan.malformed);
  EXPECT_EQ(plan.reason, "target or direction is not finite");
}

TEST(PlanCommand, HomeParksFromOutsideTheRingAndGrippersNeedNoMotion) {
  const PlannerConfig config = planner_config(Workspace{});
  // Straight up: the tool point on the base axis, inside the ring's hole.
  const JointVector upright = joints_from_degrees(0, 90, -90, 0, 0, 0);
  Command home;
  home.kind = CommandKind::Home;
  const MotionPlan parked = plan_command(config, home, upright);
  ASSERT_TRUE(parked.ok()) << parked.reason;
  ASSERT_EQ(parked.steps.size(), 1u);
  const Eigen::Vector3d tool = step_ends(config, parked)[0];
  EXPECT_NEAR(tool.head<2>().norm(), config.home_radius, 1e-6);
  EXPECT_NEAR(tool.z(), config.home_height, 1e-6);

  Command close;
  close.kind = CommandKind::CloseGripper;
  const MotionPlan closing = plan_command(config, close, upright);
  ASSERT_TRUE(closing.ok());
  ASSERT_EQ(closing.steps.size(), 1u);
  EXPECT_EQ(closing.steps[0].kind, MotionStep::Kind::CloseGripper);
}

TEST(PlanCommand, GraspOpensDescendsClosesAndLifts) {
  const PlannerConfig config = planner_config(Workspace{});
  Command grasp;
  grasp.kind = CommandKind::Grasp;
  grasp.target_position = {0.25, 0.05, 0.0};
  grasp.height = 0.05;
  const MotionPlan plan = plan_command(config, grasp, home_joints(config));
  ASSERT_TRUE(plan.ok()) << plan.reason;
  std::vector<MotionStep::Kind> kinds;
  for (const MotionStep& s : plan.steps) kinds.push_back(s.kind);
  EXPECT_EQ(kinds, (std::vector<MotionStep::Kind>{MotionStep::Kind::OpenGripper, MotionStep::Kind::Move,
                                                  MotionStep::Kind::Path, MotionStep::Kind::CloseGripper,
                                                  MotionStep::Kind::Path}));
  const Eigen::Vector3d grasped = step_ends(config, plan)[1];  // the end of the descent
  EXPECT_LT((grasped - Eigen::Vector3d(0.25, 0.05, 0.05)).norm(), 1e-6);
}

TEST(CheckSteps, PathsMustStartWhereTheArmWillBe) {
  const PlannerConfig config = planner_config(Workspace{});
  const JointVector home = home_joints(config);
  MotionStep jump;
  jump.kind = MotionStep::Kind::Path;
  jump.what = "the jump";
  jump.path = {home + JointVector::Constant(0.1), home};
  SafetyConfig safety = config.safety;
  safety.table_z = config.base.table_z();
  EXPECT_EQ(check_steps(config.model, safety, {jump}, home), "the jump does not start where the arm will be");
  MotionStep below;
  below.kind = MotionStep::Kind::Move;
  below.what = "the dive";
  below.goal = joints_from_degrees(0, -30, -60, 0, 0, 0);  // the forearm through the table
  EXPECT_TRUE(contains(check_steps(config.model, safety, {below}, home), "the dive ends unsafe")) <<
      check_steps(config.model, safety, {below}, home);
}

// ---------------------------------------------------------------- the simulated arm driver

TEST(SimulatedArm, GripperTravelsAtItsSpeedAndStopsWhenTold) {
  const ArmModel model = puma260();
  SimulatedArm arm(model.limits, JointVector::Zero(), 0.05);
  EXPECT_DOUBLE_EQ(arm.read_joint_state().gripper_opening, FakeDriver::kGripperOpen);
  EXPECT_FALSE(arm.read_joint_state().moving);
  EXPECT_EQ(arm.close_gripper(), "");
  EXPECT_TRUE(arm.read_joint_state().moving);
  arm.advance(1.0);  // 5 cm of the 10
  EXPECT_NEAR(arm.read_joint_state().gripper_opening, FakeDriver::kGripperOpen - 0.05, 1e-12);
  EXPECT_TRUE(arm.read_joint_state().moving);
  arm.stop();
  arm.advance(1.0);
  EXPECT_NEAR(arm.read_joint_state().gripper_opening, FakeDriver::kGripperOpen - 0.05, 1e-12);
  EXPECT_FALSE(arm.read_joint_state().moving);
  arm.close_gripper();
  arm.advance(5.0);
  EXPECT_DOUBLE_EQ(arm.read_joint_state().gripper_opening, 0.0);
  EXPECT_FALSE(arm.read_joint_state().moving);
}

TEST(SimulatedArm, FollowsJointTargetsAndRefusesABadSpeed) {
  const ArmModel model = puma260();
  SimulatedArm arm(model.limits, JointVector::Zero(), 0.05);
  const JointVector goal = joints_from_degrees(10, 20, -30, 0, 10, 0);
  ASSERT_EQ(arm.send_joint_targets({{1.0, goal}}), "");
  arm.advance(0.5);
  EXPECT_LT((arm.read_joint_state().position - 0.5 * goal).norm(), 1e-9);
  arm.advance(0.5);
  EXPECT_LT((arm.read_joint_state().position - goal).norm(), 1e-9);
  EXPECT_THROW(SimulatedArm(model.limits, JointVector::Zero(), 0.0), std::invalid_argument);
  EXPECT_THROW(SimulatedArm(model.limits, JointVector::Zero(), std::nan("")), std::invalid_argument);
}
