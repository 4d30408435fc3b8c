// Physics: determinism, restored states, pushes that slide or tip objects.
#include "sim_test_helpers.hpp"


using namespace nudge::sim;
using namespace nudge::sim::test;

// ---------------------------------------------------------------- physics

TEST(SimPhysics, DeterministicForSceneAndSeed) {
  Scene scene = load_scene(scene_path("three_objects.yaml"));
  scene.physics.position_jitter = 0.01;
  auto run = [](const Scene& s) {
    World w(s);
    w.push(Eigen::Vector3d(0.22, 0.04, 0.03), Eigen::Vector3d(0.22, 0.09, 0.03), 0.05, 0.2);
    w.step(200);
    return w.state();
  };
  const std::vector<double> first = run(scene);
  const std::vector<double> second = run(scene);
  ASSERT_EQ(first.size(), second.size());
  for (size_t i = 0; i < first.size(); ++i) ASSERT_EQ(first[i], second[i]) << "state " << i;
  scene.seed = 2;  // another seed, another placement
  const std::vector<double> third = run(scene);
  double diff = 0;
  for (size_t i = 0; i < first.size(); ++i) diff += std::fabs(first[i] - third[i]);
  EXPECT_GT(diff, 1e-4);
}

TEST(SimPhysics, RestoredStateReplaysExactly) {
  World world(load_scene(scene_path("three_objects.yaml")));
  world.set_pusher(Eigen::Vector3d(0.22, 0.05, 0.03), M_PI / 2);
  world.step(50);
  const std::vector<double> saved = world.state();
  auto run = [&world]() {
    for (int k = 0; k < 300; ++k) {
      world.set_pusher(Eigen::Vector3d(0.22, 0.05 + 1e-4 * k, 0.03), M_PI / 2);
      world.step();
    }
    return world.state();
  };
  const std::vector<double> first = run();
  world.set_state(saved);
  EXPECT_EQ(world.state(), saved);
  const std::vector<double> second = run();
  EXPECT_EQ(first, second);
  EXPECT_NE(first, saved);
  EXPECT_THROW(world.set_state(std::vector<double>(3, 0.0)), std::invalid_argument);
}

TEST(SimPhysics, ObjectsLeftAloneStayStill) {
  World world(load_scene(scene_path("three_objects.yaml")));
  std::vector<ObjectState> before;
  for (int i = 0; i < world.num_objects(); ++i) before.push_back(world.object(i));
  world.step_for(10.0);
  EXPECT_NEAR(world.time(), 10.0, 1e-6);
  for (int i = 0; i < world.num_objects(); ++i) {
    const ObjectState after = world.object(i);
    const double drift = (after.position - before[i].position).norm();
    std::printf("%s: drift over 10 s %.2e m, tilt %.3f deg\n", after.name.c_str(), drift,
                after.tilt() / kDeg);
    EXPECT_LT(drift, 1e-4) << after.name;
    EXPECT_LT(after.orientation.angularDistance(before[i].orientation), 1e-3) << after.name;
    EXPECT_LT(after.tilt(), 0.5 * kDeg) << after.name;
  }
}

namespace {

struct PushOutcome {
  double moved = 0;  // horizontal displacement of the base, m
  double tilt = 0;   // final tilt, rad
  bool contact = false;
};

// Pushes a lone object of `kind` at (0.25, 0) along +y with the pad's centre at `height`,
// the pad's face travelling `past` metres beyond where it first touches the object.
PushOutcome push_object(const std::string& kind, double height, double past, double speed = 0.05) {
  World world(one_object(kind));
  const Eigen::Vector3d start = world.object(0).position;
  const double touch = radius_at(kind, height) + pusher_pad_half_size().x();
  const PushResult r = world.push(Eigen::Vector3d(0.25, -touch - 0.04, height),
                                  Eigen::Vector3d(0.25, -touch + past, height), speed, 1.5);
  const ObjectState end = world.object(0);
  PushOutcome out;
  out.moved = (end.position - start).head<2>().norm();
  out.tilt = end.tilt();
  out.contact = r.contact;
  std::printf("push %s at %.3f m by %.3f m: moved %.4f m, tilt %.1f deg\n", kind.c_str(), height,
              past, out.moved, out.tilt / kDeg);
  return out;
}

}  // namespace

TEST(SimPhysics, LowPushSlidesACupWithoutTipping) {
  const PushOutcome o = push_object("cup", 0.02, 0.03);
  EXPECT_TRUE(o.contact);
  EXPECT_GT(o.moved, 0.01);
  EXPECT_LT(o.moved, 0.035);
  EXPECT_LT(o.tilt, 3 * kDeg);
}

TEST(SimPhysics, HighPushTipsATallEmptyBottle) {
  // The same push (8 cm past first touch at 5 cm/s) low down slides the bottle upright;
  // 15 cm up it tips it over.
  const PushOutcome low = push_object("bottle", 0.02, 0.08);
  EXPECT_TRUE(low.contact);
  EXPECT_GT(low.moved, 0.05);
  EXPECT_LT(low.tilt, 3 * kDeg);
  const PushOutcome high = push_object("bottle", 0.15, 0.08);
  EXPECT_TRUE(high.contact);
  EXPECT_GT(high.tilt, 60 * kDeg);
}

// Thesis ch. 6: a nudge perpendicular to the camera's line of sight moves the object across the
// image: its ground-truth symmetry line shifts in R while staying upright (theta nearly constant).
TEST(SimPhysics, NudgeAcrossTheViewShiftsTheSymmetryLine) {
  World world(one_object("cup"));
  const ImageLine before = world.axis_in_image(0, 1);
  const double touch = radius_at("cup", 0.02) + pusher_pad_half_size().x();
  world.push(Eigen::Vector3d(0.25, -touch - 0.03, 0.02), Eigen::Vector3d(0.25, -touch + 0.03, 0.02));
  const ImageLine after = world.axis_in_image(0, 1);
  ASSERT_TRUE(before.valid && after.valid);
  std::printf("nudge: R %.1f -> %.1f px, theta %.2f -> %.2f deg\n", before.r, after.r,
              before.theta / kDeg, after.theta / kDeg);
  EXPECT_GT(std::fabs(after.r - before.r), 20);  // ~3 cm at ~0.7 m: ~25 px
  EXPECT_LT(std::fabs(after.theta - before.theta), 3 * kDeg);
}

TEST(SimPhysics, PlacedObjectsSettleWhereTheyArePut) {
  World world(one_object("mug"));
  world.place_object(0, Eigen::Vector2d(0.3, 0.05), 0.5);
  world.step_for(1.0);
  const ObjectState st = world.object(0);
  EXPECT_NEAR(st.position.x(), 0.3, 1e-4);
  EXPECT_NEAR(st.position.y(), 0.05, 1e-4);
  EXPECT_LT(st.tilt(), 0.5 * kDeg);
  const Eigen::Vector3d handle = st.orientation * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(handle.y(), handle.x()), 0.5, 1e-3);
}


TEST(SimPhysics, PushStartingInsideAnObjectIsRefused) {
  World world(one_object("cup"));
  EXPECT_THROW(world.push(Eigen::Vector3d(0.25, -0.02, 0.03), Eigen::Vector3d(0.25, 0.05, 0.03)),
               SimError);
  EXPECT_FALSE(world.pusher_in_contact());
}
