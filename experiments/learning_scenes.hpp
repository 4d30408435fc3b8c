#pragma once
// The scenes of the object-learning experiment (thesis sec. 7.4, Table 7.1; issue 11): the seven
// bottles, the ten objects never learned, the seven training scenes and the 38 test images, all
// drawn from seeds fixed in advance (docs/sim.md, "The learning experiment's scenes").
// Label pictures are Debian's opencv-doc photographs; none of `building`, `home`, `graf1`,
// `fruits`, `box`, `box_in_scene` (kept for evaluation on pictures nothing was tuned on).
#include "nudge/sim/scene.hpp"
#include "nudge/sim/world.hpp"

#include <opencv2/core.hpp>

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace nudge::experiments {

// Where the label pictures come from (the opencv-doc package, scripts/lib.sh).
std::string opencv_doc_data();

// The seven bottles of Table 7.1 (white, yellow, green, brown, reflective, half-transparent,
// transparent), each with a label picture. Positions are set by the scenes that use them.
std::vector<sim::ObjectSpec> learning_bottles();
// Ten objects never learned: cans, cups, mugs, two bottles of the same shape with other labels,
// and a carton from a mesh file (experiments/scenes/learning/meshes/carton.obj).
std::vector<sim::ObjectSpec> unknown_objects(const std::string& source_dir);

// The training scene of bottle `index` (0..6): the bottle alone in the arm's workspace, arm
// present, plain table and wall, as YAML text (seed 7001 + index).
std::string training_scene_yaml(int index);

enum class TestVariant { Plain, Cluttered, Orientation, Occluded, Unknown };
enum class TestCamera { Still, Video };
// "still" | "video"; throws std::invalid_argument naming the unknown name.
TestCamera test_camera_from_name(const std::string& name);
const char* variant_name(TestVariant v);

// One test image: what is in it and how it was drawn.
struct TestImage {
  std::string name;       // e.g. "t03_green_bottle_occluded", "u07_plate_mug"
  std::string target;     // the learned bottle shown, "" for the never-learned images
  TestVariant variant = TestVariant::Plain;
  uint64_t seed = 0;
  sim::Scene scene;       // objects[0] is the target (or the unknown object)
  bool lying = false;     // objects[0] is laid on its side after the world is built
  double lying_yaw = 0, lying_roll = 0;
  cv::Mat colour;         // right camera, BGR: 1280x960 still (TestCamera::Still) or 640x480 video frame
  cv::Mat mask;           // CV_8U, object index + 1
  cv::Mat surface;        // CV_32FC3, object-frame coordinates (World::render_surface)
  double visible_fraction = 1;  // of objects[0]'s pixels had nothing been in front of it
};

// The 28 test images (four per bottle) and the 10 never-learned ones. `set` "eval" uses the
// seeds fixed for the experiment (image i, attempt k: 7100000 + 1000 k + i; an attempt is redrawn
// when the target would touch the image border, be hidden by a distracter, or, for the occluded
// variant, be less than 35 % or more than 80 % visible); "dev" another series (9100000 + ...) to
// tune on.
// Renders each with the simulator (right camera). Throws std::runtime_error if a scene cannot be
// drawn within its retries.
// `camera` chooses the right camera's image: its high-resolution still (1280x960, what the robot
// takes when it looks closely, and learns from) or its 640x480 video frame (the images of the
// first runs). The scenes are the same either way: a draw's conditions are judged on the video frame.
// `before_image(name)`, when given, is called before each image is drawn (for progress output).
std::vector<TestImage> make_test_images(const std::string& source_dir, const std::string& set,
                                        TestCamera camera = TestCamera::Still,
                                        const std::function<void(const std::string& name)>& before_image = {});

// The images nudge-exp-learning-scenes --out DIR wrote, read back from DIR/manifest.json: name,
// target, variant, seed, visible fraction, colour, mask and surface (not the scene). `set` is
// what manifest.json must say it holds. Throws std::runtime_error naming the file that is
// missing, unreadable or of another set.
std::vector<TestImage> read_test_images(const std::string& dir, const std::string& set);

}  // namespace nudge::experiments
