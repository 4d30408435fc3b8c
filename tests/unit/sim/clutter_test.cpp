// The busy-table scene family of issue 14 (nudge/sim/clutter.hpp).
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <set>
#include <unistd.h>

#include "nudge/sim/clutter.hpp"
#include "nudge/sim/objects.hpp"

namespace sim = nudge::sim;
namespace fs = std::filesystem;

namespace {

// Two small PNG "photographs" in a fresh directory.
struct Pictures {
  fs::path dir = fs::temp_directory_path() / ("nudge_clutter_test_" + std::to_string(::getpid()));
  sim::ClutterOptions options;
  Pictures() {
    fs::create_directories(dir);
    cv::Mat image(32, 48, CV_8UC3, cv::Scalar(40, 120, 200));
    for (const char* name : {"wall.png", "table.png"}) cv::imwrite((dir / name).string(), image);
    options.backdrops = {(dir / "wall.png").string()};
    options.tables = {(dir / "table.png").string()};
  }
  ~Pictures() { fs::remove_all(dir); }
};

double radius_of(const sim::ObjectSpec& o) { return sim::make_object(o.kind, 12).max_radius + (o.kind == "mug" ? 0.02 : 0); }

}  // namespace

TEST(SimClutter, SeededScenesKeepTheirRules) {
  const Pictures pictures;
  int close_pairs = 0;
  std::set<std::string> kinds;
  for (uint64_t seed = 1; seed <= 12; ++seed) {
    const sim::Scene scene = sim::clutter_scene(seed, pictures.options);
    EXPECT_EQ(sim::scene_yaml(scene, "", ""), sim::scene_yaml(sim::clutter_scene(seed, pictures.options), "", ""));
    ASSERT_GE(scene.objects.size(), 4u);
    ASSERT_LE(scene.objects.size(), 8u);
    EXPECT_TRUE(scene.render.shadows);
    EXPECT_EQ(scene.table.kind, sim::Appearance::Kind::Image);
    EXPECT_EQ(scene.background.kind, sim::Appearance::Kind::Image);
    if (scene.objects.size() >= 5) {
      std::set<std::string> here;
      for (const auto& o : scene.objects) here.insert(o.kind);
      EXPECT_EQ(here.size(), sim::object_kinds().size()) << "seed " << seed << ": every kind";
    }
    for (size_t i = 0; i < scene.objects.size(); ++i) {
      const auto& a = scene.objects[i];
      kinds.insert(a.kind);
      const double range = a.position.norm();
      EXPECT_GE(range, pictures.options.ring_inner);
      EXPECT_LE(range, pictures.options.ring_outer);
      for (size_t j = i + 1; j < scene.objects.size(); ++j) {
        const auto& b = scene.objects[j];
        const double gap = (a.position - b.position).norm() - radius_of(a) - radius_of(b);
        EXPECT_GE(gap, 0.8 * pictures.options.min_gap - 1e-9) << "seed " << seed << ": objects overlap";
        close_pairs += gap <= pictures.options.max_gap + 1e-9;
      }
    }
  }
  EXPECT_GE(close_pairs, 12);  // neighbours 3-5 cm apart in every scene on average
  EXPECT_EQ(kinds.size(), sim::object_kinds().size());
  EXPECT_NE(sim::scene_yaml(sim::clutter_scene(1, pictures.options), "", ""),
            sim::scene_yaml(sim::clutter_scene(2, pictures.options), "", ""));
}

TEST(SimClutter, SceneFileReadsBackToTheSameScene) {
  const Pictures pictures;
  const sim::Scene scene = sim::clutter_scene(7, pictures.options);
  const fs::path file = pictures.dir / "scene.yaml";
  std::ofstream(file) << sim::scene_yaml(scene, "a test scene\nsecond comment line", pictures.dir.string());
  const sim::Scene loaded = sim::load_scene(file.string());
  ASSERT_EQ(loaded.objects.size(), scene.objects.size());
  EXPECT_EQ(loaded.seed, scene.seed);
  EXPECT_EQ(fs::path(loaded.table.file), fs::path(scene.table.file));
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    EXPECT_EQ(loaded.objects[i].kind, scene.objects[i].kind);
    EXPECT_NEAR((loaded.objects[i].position - scene.objects[i].position).norm(), 0, 1e-3);
    EXPECT_NEAR(loaded.objects[i].appearance.opacity, scene.objects[i].appearance.opacity, 1e-3);
  }
}

TEST(SimClutter, RefusesReservedPicturesAndBadOptions) {
  EXPECT_TRUE(sim::is_reserved_picture("/usr/share/doc/opencv-doc/examples/data/box_in_scene.png"));
  EXPECT_TRUE(sim::is_reserved_picture("textures/home.png"));
  EXPECT_FALSE(sim::is_reserved_picture("textures/boxes.png"));
  Pictures pictures;
  sim::ClutterOptions o = pictures.options;
  o.tables = {"textures/fruits.png"};
  EXPECT_THROW(sim::clutter_scene(1, o), std::invalid_argument);
  o = pictures.options;
  o.backdrops.clear();
  EXPECT_THROW(sim::clutter_scene(1, o), std::invalid_argument);
  o = pictures.options;
  o.min_objects = 9;
  EXPECT_THROW(sim::clutter_scene(1, o), std::invalid_argument);
}

TEST(SimClutter, CommittedFamilyLoads) {
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes/clutter")) {
    if (entry.path().extension() != ".yaml") continue;
    const sim::Scene scene = sim::load_scene(entry.path().string());
    EXPECT_GE(scene.objects.size(), 4u) << entry.path();
    EXPECT_FALSE(sim::is_reserved_picture(scene.table.file));
    EXPECT_FALSE(sim::is_reserved_picture(scene.background.file));
    ++scenes;
  }
  EXPECT_EQ(scenes, 62);  // development 1-40, evaluation 1001-1010, held-out 2001-2012 (docs/clutter.md)
}
