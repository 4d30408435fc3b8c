// The gripper: lift, turn and put back a bottle; determinism.
#include "sim_test_helpers.hpp"

using namespace nudge::sim;
using namespace nudge::sim::test;

// ---------------------------------------------------------------- the gripper

namespace {

// Moves the gripper's tool point in a straight line (and its yaw linearly) over `seconds`,
// stepping physics, then holds the end pose for `pause` seconds.
void move_gripper(World& world, const Eigen::Vector3d& from, const Eigen::Vector3d& to, double yaw_from,
                  double yaw_to, double opening, double seconds, double pause) {
  const int steps = std::max(1, static_cast<int>(std::lround(seconds / world.timestep())));
  for (int k = 1; k <= steps; ++k) {
    const double f = static_cast<double>(k) / steps;
    world.set_end_effector(from + f * (to - from), yaw_from + f * (yaw_to - yaw_from), opening);
    world.step();
  }
  world.step_for(pause);
}

struct LiftTurnPlace {
  double closed_opening = 0;  // m, the fingers on the bottle
  double lift = 0;            // m, the base's rise after the 5 cm lift
  double turned_drop = 0;     // m, how far it slipped down in the fingers while turning
  double worst_tilt = 0;      // rad, while held
  double worst_lag = 0;       // rad, the bottle's yaw behind the wrist's after a turn
  bool held_throughout = true;
  bool released = false;
  double offset = 0;          // m, horizontal, of the base after putting back
  double height = 0;          // m, of the base after putting back
  double tilt = 0;            // rad, after putting back
};

// Thesis ch. 7's check with the gripper: from 25 cm above, open, down around the bottle (tool
// point `grasp` above the table, `miss` off its axis, fingers closing across `yaw0`), close, lift
// 5 cm at 5 cm/s, twelve 30 deg wrist turns (0.5 s each) pausing 0.25 s after each, down, open,
// up, away, 1 s to settle.
LiftTurnPlace lift_turn_place(const Scene& scene, double grasp, const Eigen::Vector2d& miss, double yaw0) {
  World world(scene);
  const ObjectState start = world.object(0);
  const double open = gripper_geometry().max_opening;
  const Eigen::Vector3d at(start.position.x() + miss.x(), start.position.y() + miss.y(), grasp);
  const Eigen::Vector3d above = at + Eigen::Vector3d(0, 0, 0.25 - grasp);
  const Eigen::Vector3d lifted = at + Eigen::Vector3d(0, 0, 0.05);
  LiftTurnPlace r;
  move_gripper(world, above, at, yaw0, yaw0, open, 1.0, 0.2);
  EXPECT_TRUE(world.gripper_in_use());
  EXPECT_NEAR(world.gripper_opening(), open, 1e-3);
  EXPECT_FALSE(world.pusher_in_contact()) << "the open fingers clear the bottle";
  EXPECT_LT((world.object(0).position - start.position).norm(), 1e-4);
  move_gripper(world, at, at, yaw0, yaw0, 0.0, 0.5, 0.3);
  r.closed_opening = world.gripper_opening();
  r.held_throughout = world.gripper_holds(0);
  move_gripper(world, at, lifted, yaw0, yaw0, 0.0, 1.0, 0.3);
  const double lifted_z = world.object(0).position.z();
  r.lift = lifted_z - start.position.z();
  double yaw = yaw0;
  for (int k = 0; k < 12; ++k) {
    move_gripper(world, lifted, lifted, yaw, yaw + 30 * kDeg, 0.0, 0.5, 0.25);
    yaw += 30 * kDeg;
    const ObjectState held = world.object(0);
    r.worst_tilt = std::max(r.worst_tilt, held.tilt());
    const Eigen::Vector3d x = (held.orientation * start.orientation.inverse()) * Eigen::Vector3d::UnitX();
    r.worst_lag = std::max(r.worst_lag, std::fabs(std::remainder(yaw - yaw0 - std::atan2(x.y(), x.x()), 2 * M_PI)));
    r.held_throughout = r.held_throughout && world.gripper_holds(0);
  }
  r.turned_drop = lifted_z - world.object(0).position.z();
  move_gripper(world, lifted, at, yaw, yaw, 0.0, 1.0, 0.3);
  move_gripper(world, at, at, yaw, yaw, open, 0.5, 0.3);
  r.released = !world.gripper_holds(0);
  move_gripper(world, at, above, yaw, yaw, open, 1.0, 0.0);
  world.park_pusher();
  world.step_for(1.0);
  const ObjectState end = world.object(0);
  r.offset = (end.position - start.position).head<2>().norm();
  r.height = end.position.z() - start.position.z();
  r.tilt = end.tilt();
  std::printf("closed at %.1f mm, lifted %.1f mm, slipped %.2f mm while turning, tilt <= %.2f deg, yaw lag <= %.2f "
              "deg; put back %.3f mm off, base %.3f mm, tilt %.3f deg\n",
              r.closed_opening * 1e3, r.lift * 1e3, r.turned_drop * 1e3, r.worst_tilt / kDeg, r.worst_lag / kDeg,
              r.offset * 1e3, r.height * 1e3, r.tilt / kDeg);
  return r;
}

// `lift_slip`: how far the bottle may sink in the fingers while it is lifted 5 cm.
void expect_lift_turn_place(const LiftTurnPlace& r, double bottle_diameter, double lift_slip = 0.003) {
  EXPECT_NEAR(r.closed_opening, bottle_diameter, 0.005) << "the fingers stop on the bottle";
  EXPECT_TRUE(r.held_throughout);
  EXPECT_NEAR(r.lift, 0.05, lift_slip);
  EXPECT_LT(r.turned_drop, 0.003);
  EXPECT_LT(r.worst_tilt, 3 * kDeg);
  EXPECT_LT(r.worst_lag, 2 * kDeg) << "the bottle turns with the wrist";
  EXPECT_TRUE(r.released);
  EXPECT_LT(r.offset, 0.01);  // issue 4: within 1 cm
  EXPECT_NEAR(r.height, 0.0, 1e-3);
  EXPECT_LT(r.tilt, 2 * kDeg);
}

}  // namespace

// Issue 4's last physics check (thesis ch. 7): the gripper lifts a bottle 5 cm, turns it 360 deg in
// twelve 30 deg steps, puts it back and lets go; the bottle ends up within 1 cm of where it
// started, upright. Held by the fingers' contacts and friction only (no weld to the hand).
TEST(SimGripper, LiftsTurnsAndPutsBackABottle) {
  expect_lift_turn_place(lift_turn_place(one_object("bottle"), 0.06, Eigen::Vector2d::Zero(), 0.0), 0.07);
}

// The same with a half-full bottle (0.3 kg of water, low down), grasped 4 mm off its axis with
// the fingers closing across 20 deg: the grooves centre it; it comes back within 1 cm.
TEST(SimGripper, LiftsTurnsAndPutsBackAHalfFullBottleGraspedOffCentre) {
  Scene scene = one_object("bottle");
  scene.objects[0].fill = 0.5;
  expect_lift_turn_place(lift_turn_place(scene, 0.06, Eigen::Vector2d(0.003, -0.0027), 20 * kDeg), 0.07);
}

// Only the tool in use is drawn: the open gripper in front of a cup hides other pixels of it than
// the pad there does, and neither shows in the masks' labels or when pusher_visible is off.
TEST(SimGripper, OnlyTheToolInUseIsDrawn) {
  World world(one_object("cup"));
  world.set_state(world.state());  // body positions of the current state (after a step they lag)
  const cv::Mat alone = world.render_mask(1);
  const int visible = cv::countNonZero(alone == 1);
  // Between the cup and the cameras, the fingers closing along x (one in front of the other).
  const Eigen::Vector3d front(0.36, 0.0, 0.05);
  world.set_pusher(front, M_PI / 2);
  world.set_state(world.state());  // derived positions for rendering, nothing steps
  const cv::Mat pad = world.render_mask(1);
  world.set_end_effector(front, M_PI / 2, gripper_geometry().max_opening);
  world.set_state(world.state());
  const cv::Mat gripper = world.render_mask(1);
  world.pusher_visible = false;
  const cv::Mat hidden = world.render_mask(1);
  world.pusher_visible = true;
  const int by_pad = cv::countNonZero((alone == 1) & (pad == 0));
  const int by_gripper = cv::countNonZero((alone == 1) & (gripper == 0));
  const int pad_only = cv::countNonZero((pad == 0) & (gripper == 1));
  const int gripper_only = cv::countNonZero((gripper == 0) & (pad == 1));
  std::printf("cup %d px: hidden by the pad %d, by the gripper %d; only by the pad %d, only by the gripper %d\n",
              visible, by_pad, by_gripper, pad_only, gripper_only);
  EXPECT_GT(by_pad, 300);
  EXPECT_GT(by_gripper, 300);
  EXPECT_GT(pad_only, 60) << "the pad is not drawn while the gripper is in use";
  EXPECT_GT(gripper_only, 100) << "the fingers are not drawn while the pad is in use";
  EXPECT_EQ(cv::countNonZero(hidden != alone), 0);
  EXPECT_EQ(cv::countNonZero(gripper > 1), 0) << "the gripper carries no object label";
}

// The tool's own pixels in a still (the experiment's end-effector count): the pad in front of a cup
// covers some of the cup's pixels, and the tool mask is exactly those it hides plus where it
// stands against the table; nothing where no tool is drawn, and the labels are left as they were.
TEST(SimGripper, TheToolMaskIsTheToolsOwnPixels) {
  World world(one_object("cup"));
  world.set_state(world.state());
  const cv::Mat nowhere = world.render_snapshot_tool_mask(1);
  const cv::Mat alone = world.render_snapshot_mask(1);
  world.set_pusher(Eigen::Vector3d(0.36, 0.0, 0.05), M_PI / 2);
  world.set_state(world.state());
  const cv::Mat tool = world.render_snapshot_tool_mask(1);
  const cv::Mat labels = world.render_snapshot_mask(1);
  const cv::Mat hidden_cup = (alone == 1) & (labels == 0);
  EXPECT_GT(cv::countNonZero(hidden_cup), 300);
  EXPECT_EQ(cv::countNonZero(hidden_cup & ~tool), 0) << "every cup pixel the pad hides is the tool's";
  EXPECT_EQ(cv::countNonZero(tool & (labels == 1)), 0) << "no pixel of the cup itself";
  EXPECT_LT(cv::countNonZero(nowhere & tool), cv::countNonZero(tool));
  world.pusher_visible = false;
  EXPECT_GT(cv::countNonZero(world.render_snapshot_tool_mask(1)), 300) << "drawn whatever pusher_visible says";
  EXPECT_FALSE(world.pusher_visible);
  world.pusher_visible = true;
  EXPECT_EQ(cv::countNonZero(world.render_snapshot_mask(1) != labels), 0);
}

// Gripper runs are deterministic: two Worlds given the same calls end bit-identically, and a state
// taken while the gripper holds a bottle (the fingers' commands and the tool in use are part of
// it) replays exactly. (This needed set_state() to put qpos back after mj_forward(), which
// renormalises free joints' quaternions in place and could change their last bits.)
TEST(SimGripper, DeterministicAndRestoredStatesReplay) {
  const Eigen::Vector3d at(0.25, 0.0, 0.06);
  std::vector<std::pair<Eigen::Vector3d, double>> path;  // up 3 cm turning 0.5 rad, closed
  for (int k = 1; k <= 200; ++k) path.emplace_back(at + Eigen::Vector3d(0, 0, 1.5e-4 * k), 0.0025 * k);
  auto run = [&path](World& world) {
    for (const auto& [position, yaw] : path) {
      world.set_end_effector(position, yaw, 0.0);
      world.step();
    }
    return world.state();
  };
  auto grasp = [&at](World& world) {
    move_gripper(world, at + Eigen::Vector3d(0, 0, 0.19), at, 0, 0, 0.1, 0.5, 0.0);
    move_gripper(world, at, at, 0, 0, 0.0, 0.4, 0.0);
  };
  World world(one_object("bottle")), twin(one_object("bottle"));
  const std::vector<double> pad_state = world.state();
  grasp(world);
  grasp(twin);
  const std::vector<double> saved = world.state();
  EXPECT_EQ(twin.state(), saved);
  const std::vector<double> original = run(world);
  EXPECT_EQ(run(twin), original);
  EXPECT_GT(world.object(0).position.z(), 0.02);

  world.set_state(saved);
  EXPECT_EQ(world.state(), saved);
  EXPECT_TRUE(world.gripper_in_use());
  EXPECT_EQ(run(world), original);
  world.set_state(saved);
  EXPECT_EQ(run(world), original);

  world.set_state(pad_state);
  EXPECT_FALSE(world.gripper_in_use());
  EXPECT_NEAR(world.gripper_opening(), gripper_geometry().max_opening, 1e-9);
}

// Where the supervisor grips a bottle (supervisor/grasp.hpp, grip_height: 65 mm below its estimated
// top, 170-194 mm in the learning runs for this 200 mm bottle, so 105-129 mm; 130 mm a little
// beyond): the lower row of faces on its vertical sides, the upper row at the start of the
// shoulder. Empty and half full, it is lifted, turned and put back. Gripped this high it sinks up
// to 4-5 mm in the fingers while lifted (under 1 mm at 93-110 mm), then holds while turning.
// (Gripped at the cap, 183-200 mm, the squeeze on the sloping hull of the shoulder and neck lets it
// slip 5-9 mm while turning, more with a stronger grip: why the grip is not higher.)
TEST(SimGripper, HoldsABottleWhereTheSupervisorGripsIt) {
  for (double fill : {0.0, 0.5})
    for (double grip : {0.105, 0.120, 0.130}) {
      Scene scene = one_object("bottle");
      scene.objects[0].fill = fill;
      SCOPED_TRACE("fill " + std::to_string(fill) + ", tool point at " + std::to_string(grip) + " m");
      expect_lift_turn_place(lift_turn_place(scene, grip, Eigen::Vector2d(0.002, -0.002), 10 * kDeg), 0.07, 0.006);
    }
}
