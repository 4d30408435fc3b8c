#include "learning_scenes.hpp"

#include "nudge/sim/camera.hpp"
#include "nudge/sim/truth_images.hpp"

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <locale>
#include <random>
#include <sstream>
#include <stdexcept>

namespace nudge::experiments {

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kRightCamera = 1;

sim::ObjectSpec labelled(const std::string& name, const std::string& kind, const Eigen::Vector3d& colour,
                         const std::string& picture, double bottom, double top) {
  sim::ObjectSpec o;
  o.name = name;
  o.kind = kind;
  o.appearance.colour = colour;
  o.label.file = opencv_doc_data() + "/" + picture;
  o.label.bottom = bottom;
  o.label.top = top;
  return o;
}

class Draw {
 public:
  explicit Draw(uint64_t seed) : rng_(seed) {}
  double uniform(double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng_); }
  int pick(int n) { return std::uniform_int_distribution<int>(0, n - 1)(rng_); }
  Eigen::Vector3d colour() { return {uniform(0.05, 0.95), uniform(0.05, 0.95), uniform(0.05, 0.95)}; }

 private:
  std::mt19937_64 rng_;
};

// Objects that are neither learned nor tested for: plain or checkered cups, mugs and cans.
sim::ObjectSpec distracter(Draw& draw, int index) {
  static const char* kinds[] = {"cup", "mug", "can"};
  sim::ObjectSpec o;
  o.kind = kinds[draw.pick(3)];
  o.name = "distracter" + std::to_string(index);
  o.yaw = draw.uniform(0, 2 * M_PI);
  o.appearance.colour = draw.colour();
  if (draw.pick(2) == 0) {
    o.appearance.kind = sim::Appearance::Kind::Checker;
    o.appearance.colour2 = draw.colour();
    o.appearance.repeat = 2 + draw.pick(4);
  }
  return o;
}

double footprint(const sim::ObjectSpec& o) { return sim::model_of(o, 8).max_radius; }

// Puts `o` somewhere in [x0, x1] x [y0, y1] clear of the objects already placed (1 cm apart).
bool place_clear(Draw& draw, sim::ObjectSpec& o, const std::vector<sim::ObjectSpec>& placed, double x0, double x1,
                 double y0, double y1) {
  const double r = footprint(o);
  for (int attempt = 0; attempt < 100; ++attempt) {
    o.position = Eigen::Vector2d(draw.uniform(x0, x1), draw.uniform(y0, y1));
    bool clear = true;
    for (const auto& p : placed)
      if ((p.position - o.position).norm() < r + footprint(p) + 0.01) clear = false;
    if (clear) return true;
  }
  return false;
}

const std::vector<std::string>& backdrops() {
  static const std::vector<std::string> pictures = {"stuff.jpg", "aloeL.jpg", "left01.jpg", "board.jpg",
                                                    "basketball1.png"};
  return pictures;
}

// Table, wall and light of a test image: plain for Plain, busier for the others.
void stage(Draw& draw, sim::Scene& scene, TestVariant variant) {
  scene.render.shadows = true;
  scene.render.noise_sigma = 1.5;
  scene.render.light = draw.uniform(0.45, 0.65);
  scene.render.ambient = draw.uniform(0.3, 0.4);
  scene.table.colour = Eigen::Vector3d(0.72, 0.58, 0.42) + Eigen::Vector3d::Constant(draw.uniform(-0.08, 0.08));
  if (variant == TestVariant::Plain) return;
  if (variant != TestVariant::Orientation) {
    scene.background.kind = sim::Appearance::Kind::Image;
    scene.background.file = opencv_doc_data() + "/" + backdrops()[draw.pick(static_cast<int>(backdrops().size()))];
    scene.background.repeat = 2;
  }
  if (variant != TestVariant::Unknown || draw.pick(2) == 0) {
    scene.table.kind = sim::Appearance::Kind::Checker;
    scene.table.colour2 = scene.table.colour * 0.7;
    scene.table.repeat = 20 + draw.pick(30);
  }
}

// The target's mask pixels, and whether it touches the image border, with nothing else drawn.
int solo_pixels(const TestImage& t, bool* touches_border) {
  sim::Scene solo = t.scene;
  solo.objects.resize(1);
  sim::World world(solo);
  const cv::Mat mask = [&] {
    if (!t.lying) return world.render_mask(kRightCamera);
    const sim::ObjectState o = world.object(0);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(t.lying_yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(t.lying_roll, Eigen::Vector3d::UnitZ()));
    world.set_object_pose(0, Eigen::Vector3d(o.position.x(), o.position.y(), sim::model_of(solo.objects[0], 8).max_radius), q);
    return world.render_mask(kRightCamera);
  }();
  const cv::Mat target = mask == 1;
  *touches_border = cv::countNonZero(target.row(0)) + cv::countNonZero(target.row(target.rows - 1)) +
                        cv::countNonZero(target.col(0)) + cv::countNonZero(target.col(target.cols - 1)) > 0;
  return cv::countNonZero(target);
}

// Draws the test image with the right camera: its video frame (the rig's 640x480), or its
// high-resolution still (the rig's size x scene.render.snapshot_scale, 1280x960), the image the
// robot takes when it looks closely (and learns from).
void render(TestImage& t, TestCamera camera) {
  sim::World world(t.scene);
  if (t.lying) {
    const sim::ObjectState o = world.object(0);
    const Eigen::Quaterniond q(Eigen::AngleAxisd(t.lying_yaw, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY()) *
                               Eigen::AngleAxisd(t.lying_roll, Eigen::Vector3d::UnitZ()));
    world.set_object_pose(0, Eigen::Vector3d(o.position.x(), o.position.y(), sim::model_of(t.scene.objects[0], 8).max_radius), q);
  }
  if (camera == TestCamera::Still) {
    t.colour = world.render_snapshot(kRightCamera);
    t.surface = world.render_snapshot_surface(kRightCamera, &t.mask);
  } else {
    t.colour = world.render(kRightCamera);
    t.surface = world.render_surface(kRightCamera, &t.mask);
  }
}

// Draws the scene of one test image from its seed; false if this draw does not meet the
// variant's conditions (the caller then tries the next seed of its series).
bool compose(TestImage& t, const sim::ObjectSpec& target) {
  Draw draw(t.seed);
  sim::Scene scene = sim::default_scene();
  scene.source = t.name;
  scene.seed = t.seed;
  stage(draw, scene, t.variant);
  sim::ObjectSpec main = target;
  main.yaw = draw.uniform(0, 2 * M_PI);
  main.position = Eigen::Vector2d(draw.uniform(0.21, 0.30), draw.uniform(-0.06, 0.06));
  scene.objects.push_back(main);
  int extra = 0;
  switch (t.variant) {
    case TestVariant::Plain: break;
    case TestVariant::Cluttered: extra = 3 + draw.pick(2); break;
    case TestVariant::Orientation:
      t.lying = true;
      // Within 60 deg of pointing along the view (the rig looks along -x), either end first: the
      // label is seen squeezed along the bottle's axis, up to end-on.
      t.lying_yaw = draw.uniform(-60, 60) * kDeg + (draw.pick(2) ? M_PI : 0.0);
      t.lying_roll = draw.uniform(0, 2 * M_PI);
      extra = 1;
      break;
    case TestVariant::Occluded: {
      sim::ObjectSpec occluder = distracter(draw, 0);
      occluder.name = "occluder";
      const Eigen::Vector3d camera = sim::make_rig(scene.rig).cameras[kRightCamera].centre();
      const Eigen::Vector2d towards = (camera.head<2>() - main.position).normalized();
      const Eigen::Vector2d side(-towards.y(), towards.x());
      const double gap = footprint(main) + footprint(occluder) + draw.uniform(0.01, 0.04);
      occluder.position = main.position + gap * towards + draw.uniform(-0.04, 0.04) * side;
      scene.objects.push_back(occluder);
      extra = 1 + draw.pick(2);
      break;
    }
    case TestVariant::Unknown: extra = draw.pick(3); break;
  }
  for (int k = 0; k < extra; ++k) {
    sim::ObjectSpec o = distracter(draw, k + 1);
    // Behind or beside the target, not in front of it (the Occluded variant has its occluder).
    if (!place_clear(draw, o, scene.objects, 0.02, 0.34, -0.28, 0.28)) return false;
    scene.objects.push_back(o);
  }
  if (t.lying) {  // lying along lying_yaw, the bottle needs its length clear: keep others away
    for (size_t k = 1; k < scene.objects.size(); ++k)
      if ((scene.objects[k].position - main.position).norm() < 0.25) return false;
  }
  t.scene = scene;
  try {
    sim::validate(t.scene);
  } catch (const sim::SceneError&) {
    return false;
  }
  bool border = false;
  const int alone = solo_pixels(t, &border);
  if (border || alone < 400) return false;
  // The conditions are judged on the video frame whatever the camera drawn, so that the same
  // seeds give the same scenes with either.
  render(t, TestCamera::Video);
  t.visible_fraction = static_cast<double>(cv::countNonZero(t.mask == 1)) / alone;
  if (t.variant == TestVariant::Occluded) return t.visible_fraction >= 0.35 && t.visible_fraction <= 0.8;
  return t.visible_fraction >= 0.97;
}

std::string yaml_vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << '[' << v.x() << ", " << v.y() << ", " << v.z() << ']';
  return s.str();
}

}  // namespace

std::string opencv_doc_data() { return "/usr/share/doc/opencv-doc/examples/data"; }

std::vector<sim::ObjectSpec> learning_bottles() {
  // Table 7.1's bottles: drink bottles whose labels carry the texture SIFT learns; the
  // reflective one glossy dark glass, the half-transparent frosted, the transparent clear.
  std::vector<sim::ObjectSpec> b;
  b.push_back(labelled("white_bottle", "bottle", {0.93, 0.93, 0.92}, "starry_night.jpg", 0.04, 0.115));
  b.push_back(labelled("yellow_bottle", "bottle", {0.95, 0.80, 0.15}, "HappyFish.jpg", 0.035, 0.12));
  b.push_back(labelled("green_bottle", "bottle", {0.15, 0.55, 0.20}, "butterfly.jpg", 0.03, 0.11));
  b.push_back(labelled("brown_bottle", "bottle", {0.40, 0.22, 0.08}, "baboon.jpg", 0.03, 0.12));
  b.back().appearance.specular = 0.5;
  b.push_back(labelled("reflective_bottle", "bottle", {0.22, 0.28, 0.25}, "smarties.png", 0.05, 0.10));
  b.back().appearance.specular = 1.0;
  b.back().appearance.shininess = 1.0;
  b.back().appearance.reflectance = 0.8;
  b.push_back(labelled("half_transparent_bottle", "bottle", {0.75, 0.85, 0.80}, "messi5.jpg", 0.04, 0.10));
  b.back().appearance.opacity = 0.55;
  b.push_back(labelled("transparent_bottle", "bottle", {0.85, 0.92, 0.95}, "aero1.jpg", 0.05, 0.095));
  b.back().appearance.opacity = 0.2;
  b.back().appearance.specular = 0.9;
  b.back().appearance.shininess = 0.9;
  return b;
}

std::vector<sim::ObjectSpec> unknown_objects(const std::string& source_dir) {
  std::vector<sim::ObjectSpec> u;
  u.push_back(labelled("orange_can", "can", {0.9, 0.5, 0.1}, "orange.jpg", -1, -1));
  u.push_back(labelled("apple_cup", "cup", {0.95, 0.95, 0.95}, "apple.jpg", -1, -1));
  u.push_back(labelled("chick_mug", "mug", {0.9, 0.85, 0.3}, "chicky_512.png", -1, -1));
  u.push_back(labelled("squirrel_can", "can", {0.6, 0.6, 0.62}, "squirrel_cls.jpg", -1, -1));
  sim::ObjectSpec carton;
  carton.name = "carton";
  carton.kind = "mesh";
  carton.mesh.file = source_dir + "/experiments/scenes/learning/meshes/carton.obj";
  carton.mesh.texture = opencv_doc_data() + "/cards.png";
  carton.mesh.scale = 0.001;
  carton.mesh.rotation = Eigen::Vector3d(90 * kDeg, 0, 0);
  u.push_back(carton);
  // Same shape as the learned bottles, other labels: only the labels tell them apart.
  u.push_back(labelled("whale_bottle", "bottle", {0.2, 0.35, 0.75}, "rubberwhale1.png", 0.035, 0.12));
  u.push_back(labelled("suzanne_cup", "cup", {0.3, 0.3, 0.3}, "Blender_Suzanne1.jpg", -1, -1));
  u.push_back(labelled("plate_mug", "mug", {0.8, 0.2, 0.2}, "licenseplate_motion.jpg", -1, -1));
  u.push_back(labelled("ela_can", "can", {0.85, 0.85, 0.9}, "ela_original.jpg", -1, -1));
  u.push_back(labelled("leuven_bottle", "bottle", {0.93, 0.93, 0.92}, "leuvenA.jpg", 0.04, 0.115));
  return u;
}

std::string training_scene_yaml(int index) {
  const std::vector<sim::ObjectSpec> bottles = learning_bottles();
  if (index < 0 || index >= static_cast<int>(bottles.size()))
    throw std::out_of_range("training_scene_yaml: no bottle " + std::to_string(index));
  const uint64_t seed = 7001 + index;
  Draw draw(seed);
  const sim::ObjectSpec& b = bottles[index];
  const double x = draw.uniform(0.22, 0.27), y = draw.uniform(-0.07, 0.07), yaw = draw.uniform(0, 360);
  std::ostringstream s;
  s.imbue(std::locale::classic());
  s << std::setprecision(4);
  s << "%YAML:1.0\n---\n"
    << "# Training scene " << index + 1 << " of the object-learning experiment (thesis sec. 7.4): the "
    << b.name << " alone\n# in the arm's workspace, to be nudged, grasped, turned and learned. Written by\n"
    << "# nudge-exp-learning-scenes --training-scenes (seed " << seed << ", fixed in advance; docs/sim.md).\n"
    << "seed: " << seed << "\n"
    << "table: { type: plain, colour: [0.72, 0.58, 0.42] }\n"
    << "background: { type: plain, colour: [0.9, 0.9, 0.87] }\n"
    << "arm: { present: 1, shoulder_height: 0.33, joints_deg: [0, 90, -90, 0, 0, 0] }\n"
    << "objects:\n"
    << "  - { kind: " << b.kind << ", name: " << b.name << ", position: [" << x << ", " << y << "], yaw_deg: " << yaw
    << ",\n      colour: " << yaml_vec(b.appearance.colour) << ", opacity: " << b.appearance.opacity
    << ", specular: " << b.appearance.specular << ", shininess: " << b.appearance.shininess
    << ", reflectance: " << b.appearance.reflectance << ",\n      label: { file: " << b.label.file
    << ", bottom: " << b.label.bottom << ", top: " << b.label.top << " } }\n";
  return s.str();
}

TestCamera test_camera_from_name(const std::string& name) {
  if (name == "still") return TestCamera::Still;
  if (name == "video") return TestCamera::Video;
  throw std::invalid_argument("test image camera must be still or video, not '" + name + "'");
}

const char* variant_name(TestVariant v) {
  switch (v) {
    case TestVariant::Plain: return "plain";
    case TestVariant::Cluttered: return "cluttered";
    case TestVariant::Orientation: return "orientation";
    case TestVariant::Occluded: return "occluded";
    case TestVariant::Unknown: return "unknown";
  }
  return "?";
}

std::vector<TestImage> make_test_images(const std::string& source_dir, const std::string& set, TestCamera camera,
                                        const std::function<void(const std::string& name)>& before_image) {
  if (set != "eval" && set != "dev") throw std::invalid_argument("test image set must be eval or dev, not '" + set + "'");
  // Image i's seed at its attempt k: base + 1000 k + i (eval base 7100000, dev base 9100000).
  const uint64_t first_seed = set == "eval" ? 7100000 : 9100000;
  constexpr int kTries = 40;
  std::vector<std::pair<sim::ObjectSpec, TestVariant>> plan;
  for (const auto& b : learning_bottles())
    for (TestVariant v : {TestVariant::Plain, TestVariant::Cluttered, TestVariant::Orientation, TestVariant::Occluded})
      plan.emplace_back(b, v);
  for (const auto& u : unknown_objects(source_dir)) plan.emplace_back(u, TestVariant::Unknown);
  std::vector<TestImage> images;
  for (size_t i = 0; i < plan.size(); ++i) {
    const auto& [object, variant] = plan[i];
    const bool known = variant != TestVariant::Unknown;
    std::ostringstream name;
    name << (known ? 't' : 'u') << std::setw(2) << std::setfill('0') << (known ? i + 1 : i + 1 - 28) << '_'
         << object.name;
    if (known) name << '_' << variant_name(variant);
    if (before_image) before_image(name.str());
    bool done = false;
    for (int attempt = 0; attempt < kTries && !done; ++attempt) {
      TestImage t;
      t.name = name.str();
      t.target = known ? object.name : "";
      t.variant = variant;
      t.seed = first_seed + 1000 * attempt + i;
      done = compose(t, object);
      if (!done) continue;
      if (camera != TestCamera::Video) render(t, camera);
      images.push_back(std::move(t));
    }
    if (!done) throw std::runtime_error("test image " + name.str() + ": no seed of " + std::to_string(kTries) + " drew it");
  }
  return images;
}

namespace {

cv::Mat read_png(const std::string& path, int flags) {
  cv::Mat image = cv::imread(path, flags);
  if (image.empty()) throw std::runtime_error(path + ": missing or not an image");
  return image;
}

TestVariant variant_from_name(const std::string& name, const std::string& file) {
  for (TestVariant v : {TestVariant::Plain, TestVariant::Cluttered, TestVariant::Orientation, TestVariant::Occluded,
                        TestVariant::Unknown})
    if (name == variant_name(v)) return v;
  throw std::runtime_error(file + ": unknown variant '" + name + "'");
}

}  // namespace

std::vector<TestImage> read_test_images(const std::string& dir, const std::string& set) {
  const std::string file = dir + "/manifest.json";
  std::ifstream in(file);
  if (!in) throw std::runtime_error(file + ": missing (write it with nudge-exp-learning-scenes --out " + dir + ")");
  nlohmann::json manifest;
  try {
    manifest = nlohmann::json::parse(in);
    if (manifest.at("set").get<std::string>() != set)
      throw std::runtime_error("holds the '" + manifest.at("set").get<std::string>() + "' set, not '" + set + "'");
    std::vector<TestImage> images;
    for (const auto& entry : manifest.at("images")) {
      TestImage t;
      t.name = entry.at("name").get<std::string>();
      t.target = entry.at("target").get<std::string>();
      t.variant = variant_from_name(entry.at("variant").get<std::string>(), file);
      t.seed = entry.at("seed").get<uint64_t>();
      t.visible_fraction = entry.at("visible_fraction").get<double>();
      t.colour = read_png(dir + "/" + entry.at("colour").get<std::string>(), cv::IMREAD_COLOR);
      t.mask = read_png(dir + "/" + entry.at("mask").get<std::string>(), cv::IMREAD_GRAYSCALE);
      t.surface = sim::decode_surface(read_png(dir + "/" + entry.at("surface").get<std::string>(), cv::IMREAD_UNCHANGED));
      images.push_back(std::move(t));
    }
    return images;
  } catch (const nlohmann::json::exception& e) {
    throw std::runtime_error(file + ": " + e.what());
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    if (what.rfind(dir, 0) == 0) throw;  // already names its file
    throw std::runtime_error(file + ": " + what);
  }
}

}  // namespace nudge::experiments
