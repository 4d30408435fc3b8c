// Scene files of the simulated world: the shipped scenes, errors naming the file and field.
#include "sim_test_helpers.hpp"

#include <filesystem>

using namespace nudge::sim;
using namespace nudge::sim::test;

// ---------------------------------------------------------------- scene files

TEST(SimScene, LoadsTheShippedScenes) {
  const Scene scene = load_scene(scene_path("three_objects.yaml"));
  ASSERT_EQ(scene.objects.size(), 3u);
  EXPECT_EQ(scene.objects[1].kind, "mug");
  EXPECT_EQ(scene.objects[1].name, "red_mug");
  EXPECT_NEAR(scene.objects[1].yaw, 60 * kDeg, 1e-12);
  EXPECT_EQ(scene.objects[1].appearance.kind, Appearance::Kind::Checker);
  EXPECT_NEAR(scene.objects[0].position.y(), 0.10, 1e-12);
  EXPECT_NO_THROW(load_scene(scene_path("single_cup.yaml")));
  EXPECT_FALSE(scene.arm.present);
  const Scene with_arm = load_scene(scene_path("arm_three_objects.yaml"));
  EXPECT_TRUE(with_arm.arm.present);
  EXPECT_NEAR(with_arm.arm.shoulder_height, 0.33, 1e-12);
  EXPECT_NEAR(with_arm.arm.joints[1], 90 * kDeg, 1e-12);
}

TEST(SimScene, EveryShippedSceneBuildsAndRenders) {
  int scenes = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes")) {
    if (entry.path().extension() != ".yaml") continue;
    ++scenes;
    SCOPED_TRACE(entry.path().string());
    World world(load_scene(entry.path().string()));
    const cv::Mat mask = world.render_mask(1);
    for (int i = 0; i < world.num_objects(); ++i)
      EXPECT_GT(cv::countNonZero(mask == i + 1), 300) << world.object(i).name << " not visible";
  }
  EXPECT_GE(scenes, 3);
}

TEST(SimScene, ErrorsNameTheFileAndTheField) {
  std::string path;
  std::string msg = load_error("%YAML:1.0\nobjects:\n  - { kind: teapot, position: [0.2, 0] }\n", &path);
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("objects[0].kind"), std::string::npos) << msg;
  EXPECT_NE(msg.find("teapot"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects:\n  - { kind: cup, position: [0.2, 0] }\n  - { kind: cup }\n");
  EXPECT_NE(msg.find("objects[1].position"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects:\n  - { kind: cup, position: [0.2, 0], colr: [1, 0, 0] }\n");
  EXPECT_NE(msg.find("objects[0].colr: unknown field"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\ncameras: { vergence_deg: abc }\n");
  EXPECT_NE(msg.find("cameras.vergence_deg"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nbackground: { type: image, file: no_such_file.png }\n");
  EXPECT_NE(msg.find("background.file"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects:\n  - { kind: cup, position: [0.2, 0], fill: 1.5 }\n");
  EXPECT_NE(msg.find("objects[0].fill"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects:\n  - { kind: cup, position: [0.2, 0] }\n"
                   "  - { kind: bottle, position: [0.25, 0.02] }\n");
  EXPECT_NE(msg.find("objects[1].position: overlaps objects[0]"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects:\n  - { kind: cup, position: [3.0, 0] }\n");
  EXPECT_NE(msg.find("objects[0].position: must be on the table"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nphysics: { impratio: 0.5 }\n");
  EXPECT_NE(msg.find("physics.impratio"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\narm: { present: 1, joints_deg: [0, 0, 90, 0, 0, 0] }\n");
  EXPECT_NE(msg.find("arm.joints_deg"), std::string::npos) << msg;
  EXPECT_NE(msg.find("joint 3"), std::string::npos) << msg;
  msg = load_error("%YAML:1.0\narm: { shoulder_height: 3 }\n");
  EXPECT_NE(msg.find("arm.shoulder_height"), std::string::npos) << msg;
  msg = load_error("%YAML:1.0\narm: { present: 1 }\nobjects:\n  - { kind: cup, position: [0.05, 0] }\n");
  EXPECT_NE(msg.find("pedestal"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nrender: { shadows: maybe }\n");
  EXPECT_NE(msg.find("render.shadows"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects: [1, 2\n");  // not YAML
  EXPECT_NE(msg.find("not a valid scene file"), std::string::npos) << msg;

  // OpenCV's cv::FileStorage, which read scenes before, looped for ever on this one.
  msg = load_error("%YAML:1.0\n---a%YAML:1.0\n-#e \n --\nr flagstool_l#en The a", &path);
  EXPECT_NE(msg.find(path + ": (top level): expected a map"), std::string::npos) << msg;
  msg = load_error("%YAML:1.0\nobjects: &a [*a]\n");  // an alias into itself
  EXPECT_NE(msg.find("objects[0]: expected a map"), std::string::npos) << msg;
  msg = load_error("%YAML:1.0\ncameras: { width: '640' }\n");
  EXPECT_NE(msg.find("cameras.width: expected an integer"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\ntable: { colour: [1.5, 0, 0] }\n");
  EXPECT_NE(msg.find("table.colour"), std::string::npos) << msg;

  msg = load_error("%YAML:1.0\nobjects:\n  - { kind: cup, name: a, position: [0.2, 0] }\n"
                   "  - { kind: mug, name: a, position: [0.3, 0] }\n");
  EXPECT_NE(msg.find("objects[1].name"), std::string::npos) << msg;

  try {
    load_scene("/nonexistent/scene.yaml");
    FAIL() << "no error for a missing file";
  } catch (const SceneError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.yaml"), std::string::npos);
  }
}
