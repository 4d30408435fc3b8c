// The object library: meshes, sizes, water fill.
#include "sim_test_helpers.hpp"


using namespace nudge::sim;
using namespace nudge::sim::test;

// ---------------------------------------------------------------- object library

TEST(SimObjects, MeshesAreClosedOutwardAndRealisticallySized) {
  for (const std::string& kind : object_kinds()) {
    const ObjectModel model = make_object(kind);
    ASSERT_FALSE(model.parts.empty()) << kind;
    for (const Mesh& part : model.parts) {
      EXPECT_GT(part.volume(), 0) << kind;
      EXPECT_EQ(part.texcoords.size(), part.vertices.size()) << kind;
    }
    EXPECT_GT(model.default_mass, 0) << kind;
    EXPECT_GT(model.height, 0.08) << kind;
    EXPECT_LT(model.height, 0.25) << kind;
  }
  const ObjectModel bottle = make_object("bottle");
  EXPECT_NEAR(bottle.height, 0.20, 0.005);
  EXPECT_NEAR(2 * bottle.max_radius, 0.07, 0.005);
  EXPECT_EQ(make_object("mug").parts.size(), 2u);  // body and handle
  EXPECT_THROW(make_object("teapot"), std::invalid_argument);

  // Shell mass properties: on the axis, between base and top, positive definite.
  std::vector<const Mesh*> parts{&bottle.parts[0]};
  const MassProperties props = shell_mass_properties(parts, 0.04);
  EXPECT_NEAR(props.com.x(), 0, 1e-4);
  EXPECT_NEAR(props.com.y(), 0, 1e-4);
  EXPECT_GT(props.com.z(), 0.06);
  EXPECT_LT(props.com.z(), 0.12);
  EXPECT_NEAR(props.inertia(0, 0), props.inertia(1, 1), 1e-3 * props.inertia(0, 0));
  EXPECT_GT(props.inertia(2, 2), 0);
}


TEST(SimObjects, WaterFillAddsMassLowDown) {
  // combine(): two point-like halves 2 cm apart -> com midway, inertia m d^2 / 4 about it.
  MassProperties a, b;
  a.mass = b.mass = 0.5;
  a.com = Eigen::Vector3d(0, 0, 0.01);
  b.com = Eigen::Vector3d(0, 0, -0.01);
  const MassProperties ab = combine(a, b);
  EXPECT_NEAR(ab.com.norm(), 0, 1e-12);
  EXPECT_NEAR(ab.inertia(0, 0), 1.0 * 0.02 * 0.02 / 4, 1e-12);
  EXPECT_NEAR(ab.inertia(2, 2), 0, 1e-12);

  Scene scene = one_object("bottle");
  scene.objects[0].fill = 0.5;
  scene.objects.push_back(one_object("bottle", 0.25, 0.15).objects[0]);  // empty, for comparison
  World world(scene);
  const ObjectModel bottle = make_object("bottle");
  const double water = kWaterDensity * M_PI * std::pow(bottle.liquid_radius, 2) * 0.5 * bottle.liquid_height;
  const ObjectState full = world.object(0), empty = world.object(1);
  EXPECT_NEAR(full.mass, bottle.default_mass + water, 1e-9);
  EXPECT_NEAR(empty.mass, bottle.default_mass, 1e-9);
  EXPECT_LT(full.centre_of_mass.z(), empty.centre_of_mass.z() - 0.03);
  world.step_for(2.0);
  EXPECT_LT((world.object(0).position - full.position).norm(), 1e-4);
}
