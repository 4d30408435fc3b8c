// Tests of the simulated world (common/sim): scene files, object models, the stereo rig and its
// ground truth, offscreen rendering and masks, determinism and the physics of pushes.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <unistd.h>

#include "nudge/sim/camera.hpp"
#include "nudge/sim/mjcf.hpp"
#include "nudge/sim/objects.hpp"
#include "nudge/sim/scene.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/safety.hpp"
#include "nudge/robot/puma260.hpp"

using namespace nudge::sim;

namespace {

constexpr double kDeg = M_PI / 180.0;

std::string scene_path(const std::string& name) {
  return std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes/" + name;
}

// Writes `text` to a fresh temporary .yaml file and returns its path.
std::string temp_scene(const std::string& text) {
  static int counter = 0;
  const std::string path = "/tmp/nudge_sim_test_" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter++) + ".yaml";
  std::ofstream(path) << text;
  return path;
}

// The message of the SceneError thrown when loading `text`, or "" if none is thrown.
std::string load_error(const std::string& text, std::string* path_out = nullptr) {
  const std::string path = temp_scene(text);
  if (path_out) *path_out = path;
  std::string message;
  try {
    load_scene(path);
  } catch (const SceneError& e) {
    message = e.what();
  }
  std::remove(path.c_str());
  return message;
}

Scene one_object(const std::string& kind, double x = 0.25, double y = 0.0) {
  Scene scene = default_scene();
  ObjectSpec o;
  o.kind = kind;
  o.position = Eigen::Vector2d(x, y);
  o.appearance.colour = Eigen::Vector3d(0.95, 0.95, 0.95);
  scene.objects.push_back(o);
  return scene;
}

double radius_at(const std::string& kind, double z) { return make_object(kind).radius_at(z); }

}  // namespace

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

// ---------------------------------------------------------------- cameras and ground truth

TEST(SimCamera, VergedRigGeometry) {
  const RigSpec spec;
  const StereoRig rig = make_rig(spec);
  const CameraModel& l = rig.cameras[0];
  const CameraModel& r = rig.cameras[1];
  EXPECT_NEAR((l.centre() - r.centre()).norm(), 0.25, 1e-9);
  EXPECT_NEAR(std::acos(l.forward().dot(r.forward())), 15 * kDeg, 1e-9);
  const Eigen::Vector3d mid = 0.5 * (l.centre() + r.centre());
  EXPECT_NEAR((mid - spec.target).norm(), 0.7, 1e-9);
  // Looking down ~30 degrees; the left camera is on the left of the right one.
  EXPECT_NEAR(std::asin(-l.forward().z()), 30 * kDeg, 0.5 * kDeg);
  EXPECT_LT(l.to_camera(r.centre()).x(), 0.26);
  EXPECT_GT(l.to_camera(r.centre()).x(), 0.24);
  // Intrinsics: principal point at the image centre, f from the vertical field of view.
  EXPECT_DOUBLE_EQ(l.K(0, 2), 319.5);
  EXPECT_DOUBLE_EQ(l.K(1, 2), 239.5);
  EXPECT_NEAR(l.K(1, 1), 240 / std::tan(22.5 * kDeg), 1e-9);
  // The target is in front of both cameras, near the middle of the images.
  for (const CameraModel& c : rig.cameras) {
    double depth = 0;
    const Eigen::Vector2d p = c.project(spec.target, &depth);
    EXPECT_GT(depth, 0.6);
    EXPECT_NEAR(p.x(), 319.5, 60);
    EXPECT_NEAR(p.y(), 239.5, 5);
  }
  // Extrinsics between the cameras agree with the poses.
  const Eigen::Vector3d X(0.3, 0.05, 0.1);
  EXPECT_LT((rig.R_right_left() * l.to_camera(X) + rig.t_right_left() - r.to_camera(X)).norm(), 1e-12);
}

TEST(SimCamera, LineConvention) {
  // A vertical line through x = 400: theta = 0, R = 400 - 319.5.
  ImageLine v = line_through({400, 100}, {400, 300}, 640, 480);
  ASSERT_TRUE(v.valid);
  EXPECT_NEAR(v.theta, 0, 1e-12);
  EXPECT_NEAR(v.r, 80.5, 1e-9);
  // The same line given top-down.
  v = line_through({400, 300}, {400, 100}, 640, 480);
  EXPECT_NEAR(v.theta, 0, 1e-12);
  EXPECT_NEAR(v.r, 80.5, 1e-9);
  // A horizontal line through y = 100: theta = 90 deg, R = 100 - 239.5.
  const ImageLine h = line_through({10, 100}, {600, 100}, 640, 480);
  EXPECT_NEAR(h.theta, M_PI / 2, 1e-12);
  EXPECT_NEAR(h.r, -139.5, 1e-9);
  // A tilted line: the pivot R (cos, sin) + centre lies on it; theta in (-90, 90].
  const ImageLine t = line_through({300, 400}, {340, 100}, 640, 480);
  EXPECT_GT(t.theta, -M_PI / 2);
  EXPECT_LE(t.theta, M_PI / 2);
  EXPECT_NEAR(signed_distance(t, {300, 400}, 640, 480), 0, 1e-9);
  EXPECT_NEAR(signed_distance(t, {340, 100}, 640, 480), 0, 1e-9);
  EXPECT_FALSE(line_through({5, 5}, {5, 5}, 640, 480).valid);
}

// ---------------------------------------------------------------- rendering

namespace {

// Fraction of the points sampled along the projected axis (between 10% and 90% of its height)
// that fall inside the object's mask.
double axis_inside_mask(const ImageLine& line, const cv::Mat& mask, int label) {
  int inside = 0, total = 0;
  for (double f = 0.1; f <= 0.9; f += 0.02) {
    const Eigen::Vector2d p = line.bottom + f * (line.top - line.bottom);
    const int x = static_cast<int>(std::lround(p.x())), y = static_cast<int>(std::lround(p.y()));
    ++total;
    if (x >= 0 && y >= 0 && x < mask.cols && y < mask.rows && mask.at<uchar>(y, x) == label) ++inside;
  }
  return static_cast<double>(inside) / total;
}

// Fraction of the object's mask pixels whose mirror image across the line is in the mask too.
double mirror_agreement(const ImageLine& line, const cv::Mat& mask, int label) {
  const double c = std::cos(line.theta), s = std::sin(line.theta);
  int n = 0, agree = 0;
  for (int y = 0; y < mask.rows; ++y)
    for (int x = 0; x < mask.cols; ++x) {
      if (mask.at<uchar>(y, x) != label) continue;
      const double d = signed_distance(line, {double(x), double(y)}, mask.cols, mask.rows);
      const int mx = static_cast<int>(std::lround(x - 2 * d * c));
      const int my = static_cast<int>(std::lround(y - 2 * d * s));
      ++n;
      if (mx >= 0 && my >= 0 && mx < mask.cols && my < mask.rows && mask.at<uchar>(my, mx) == label)
        ++agree;
    }
  return n ? static_cast<double>(agree) / n : 0.0;
}

}  // namespace

TEST(SimRender, StereoPairShowsTheObjectsWhereTheGroundTruthSays) {
  World world(load_scene(scene_path("three_objects.yaml")));
  const StereoImages pair = world.render_stereo(true);
  for (int c = 0; c < 2; ++c) {
    const cv::Mat& image = pair.colour[c];
    ASSERT_EQ(image.type(), CV_8UC3);
    ASSERT_EQ(image.cols, 640);
    ASSERT_EQ(image.rows, 480);
    cv::Scalar mean, stddev;
    cv::meanStdDev(image, mean, stddev);
    EXPECT_GT(stddev[0] + stddev[1] + stddev[2], 20) << "camera " << c << " image is flat";
    const cv::Mat& mask = pair.mask[c];
    ASSERT_EQ(mask.type(), CV_8U);
    ASSERT_EQ(mask.size(), image.size());
    for (int i = 0; i < world.num_objects(); ++i) {
      const int label = i + 1;
      const int pixels = cv::countNonZero(mask == label);
      EXPECT_GT(pixels, 1500) << "object " << i << " camera " << c;
      // The object's pixels look different from the table around it.
      cv::Scalar inside = cv::mean(image, mask == label);
      cv::Scalar outside = cv::mean(image, mask == 0);
      EXPECT_GT(cv::norm(inside - outside), 20) << "object " << i << " camera " << c;
      const ImageLine line = world.axis_in_image(i, c);
      ASSERT_TRUE(line.valid);
      EXPECT_GT(axis_inside_mask(line, mask, label), 0.95) << "object " << i << " camera " << c;
      // Bodies of revolution are (nearly: perspective skews slightly) mirror-symmetric about the
      // projected axis; the mug's handle breaks its symmetry.
      const double agreement = mirror_agreement(line, mask, label);
      std::printf("camera %d %-8s %5d px, axis inside %.2f, mirror agreement %.3f\n", c,
                  world.object(i).kind.c_str(), pixels, axis_inside_mask(line, mask, label),
                  agreement);
      if (world.object(i).kind == "mug")
        EXPECT_GT(agreement, 0.85) << "mug camera " << c;
      else
        EXPECT_GT(agreement, 0.95) << world.object(i).kind << " camera " << c;
    }
  }
  // The two cameras see different views of the same instant.
  EXPECT_GT(cv::norm(pair.colour[0], pair.colour[1], cv::NORM_L1), 1e5);
  // Rendering is repeatable.
  EXPECT_EQ(cv::norm(world.render(0), pair.colour[0], cv::NORM_INF), 0);
}

// The cameras' K and pose agree with MuJoCo's rendering to about a pixel: the bottle's silhouette
// (mask extremes) matches the projection of its 3D outline.
TEST(SimRender, IntrinsicsAndPosesMatchTheRenderer) {
  World world(one_object("bottle", 0.28, 0.03));
  const ObjectModel bottle = make_object("bottle");
  const Axis3d axis = world.axis(0);
  for (int c = 0; c < 2; ++c) {
    for (int hires = 0; hires < 2; ++hires) {  // the 640x480 view and the 1280x960 still
      const CameraModel cam = hires ? world.snapshot_camera(c) : world.camera(c);
      const cv::Mat mask = hires ? world.render_snapshot_mask(c) : world.render_mask(c);
      ASSERT_EQ(mask.cols, hires ? 1280 : 640);
      ASSERT_EQ(mask.rows, hires ? 960 : 480);
      // Extremes of the projected outline: circles of the profile's vertices.
      double top = 1e9, left = 1e9, right = -1e9;
      for (const auto& p : bottle.profile) {
        for (int k = 0; k < 360; ++k) {
          const double a = k * kDeg;
          const Eigen::Vector3d X =
              axis.base + Eigen::Vector3d(p.x() * std::cos(a), p.x() * std::sin(a), p.y());
          const Eigen::Vector2d u = cam.project(X);
          top = std::min(top, u.y());
          left = std::min(left, u.x());
          right = std::max(right, u.x());
        }
      }
      int mask_top = mask.rows, mask_left = mask.cols, mask_right = -1;
      for (int y = 0; y < mask.rows; ++y)
        for (int x = 0; x < mask.cols; ++x)
          if (mask.at<uchar>(y, x) == 1) {
            mask_top = std::min(mask_top, y);
            mask_left = std::min(mask_left, x);
            mask_right = std::max(mask_right, x);
          }
      // A pixel is drawn when the outline covers its centre (the mesh is a 48-gon, a hair
      // inside the circles): extremes agree within about a pixel, the middle more closely.
      const double tol = hires ? 1.5 : 1.25;
      EXPECT_NEAR(mask_top, top, tol) << "camera " << c << " hires " << hires;
      EXPECT_NEAR(mask_left, left, tol) << "camera " << c << " hires " << hires;
      EXPECT_NEAR(mask_right, right, tol) << "camera " << c << " hires " << hires;
      EXPECT_NEAR(0.5 * (mask_left + mask_right), 0.5 * (left + right), 0.75)
          << "camera " << c << " hires " << hires;
    }
  }
  const cv::Mat still = world.render_snapshot(1);
  EXPECT_EQ(still.size(), cv::Size(1280, 960));
  EXPECT_EQ(still.type(), CV_8UC3);
}

TEST(SimCamera, DistortionRoundTrip) {
  RigSpec spec;
  spec.distortion = {-0.25, 0.1, 0.001, -0.002, 0.0};
  const CameraModel cam = make_rig(spec).cameras[1];
  ASSERT_TRUE(cam.distorted());
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(0.25, 0, 0.06), Eigen::Vector3d(0.1, 0.3, 0.0),
                                  Eigen::Vector3d(0.4, -0.25, 0.2)}) {
    const Eigen::Vector2d pixel = cam.project(X);
    const Eigen::Vector3d c = cam.to_camera(X);
    const Eigen::Vector2d n = cam.undistort(pixel);
    EXPECT_NEAR(n.x(), c.x() / c.z(), 1e-9);
    EXPECT_NEAR(n.y(), c.y() / c.z(), 1e-9);
  }
  // Barrel distortion: the pinhole image that covers the corners is larger than the image.
  const PinholeCanvas canvas = pinhole_canvas(cam);
  EXPECT_GT(canvas.width, 640);
  EXPECT_GT(canvas.height, 480);
  CameraModel ideal = cam;
  ideal.distortion = {};
  EXPECT_EQ(pinhole_canvas(ideal).width, 640);
}

// With lens distortion the renderer warps a larger pinhole image: silhouettes still land where
// the distorted camera model projects them, and the corners are filled.
TEST(SimRender, DistortedCamerasMatchTheirModel) {
  Scene scene = one_object("bottle", 0.22, -0.12);
  scene.rig.distortion = {-0.25, 0.08, 0.0, 0.0, 0.0};
  World world(scene);
  const ObjectModel bottle = make_object("bottle");
  const Axis3d axis = world.axis(0);
  for (int c = 0; c < 2; ++c) {
    const CameraModel& cam = world.camera(c);
    const cv::Mat mask = world.render_mask(c);
    const cv::Mat image = world.render(c);
    ASSERT_EQ(image.size(), cv::Size(640, 480));
    for (const cv::Point corner : {cv::Point(0, 0), cv::Point(639, 0), cv::Point(0, 479), cv::Point(639, 479)}) {
      const cv::Vec3b px = image.at<cv::Vec3b>(corner);
      EXPECT_GT(px[0] + px[1] + px[2], 60) << "corner " << corner << " camera " << c;
    }
    double left = 1e9, right = -1e9;
    for (const auto& p : bottle.profile)
      for (int k = 0; k < 360; ++k) {
        const double a = k * kDeg;
        const Eigen::Vector2d u = cam.project(
            axis.base + Eigen::Vector3d(p.x() * std::cos(a), p.x() * std::sin(a), p.y()));
        left = std::min(left, u.x());
        right = std::max(right, u.x());
      }
    int mask_left = mask.cols, mask_right = -1;
    for (int y = 0; y < mask.rows; ++y)
      for (int x = 0; x < mask.cols; ++x)
        if (mask.at<uchar>(y, x) == 1) {
          mask_left = std::min(mask_left, x);
          mask_right = std::max(mask_right, x);
        }
    EXPECT_NEAR(mask_left, left, 1.5) << "camera " << c;
    EXPECT_NEAR(mask_right, right, 1.5) << "camera " << c;
  }
  EXPECT_EQ(world.render_snapshot(0).size(), cv::Size(1280, 960));
}

TEST(SimRender, ImageTexturesFromPngFiles) {
  // A 64x64 two-colour stripe texture next to a scene file that refers to it relatively.
  const std::string dir = "/tmp/nudge_sim_test_tex_" + std::to_string(::getpid());
  std::filesystem::create_directories(dir);
  cv::Mat stripes(64, 64, CV_8UC3, cv::Scalar(40, 40, 200));
  for (int x = 0; x < 64; x += 16) stripes.colRange(x, x + 8).setTo(cv::Scalar(230, 230, 230));
  ASSERT_TRUE(cv::imwrite(dir + "/stripes.png", stripes));
  std::ofstream(dir + "/scene.yaml")
      << "%YAML:1.0\ntable: { type: image, file: stripes.png, repeat: 8 }\n"
         "objects:\n  - { kind: bottle, position: [0.25, 0], type: image, file: stripes.png }\n";
  const Scene scene = load_scene(dir + "/scene.yaml");
  EXPECT_EQ(scene.table.file, dir + "/stripes.png");
  World world(scene);
  const cv::Mat image = world.render(0);
  const cv::Mat mask = world.render_mask(0);
  // Both colours of the texture show on the table (reddish and whitish pixels).
  cv::Mat channels[3];
  cv::split(image, channels);
  const cv::Mat table = mask == 0;
  EXPECT_GT(cv::countNonZero((channels[2] > channels[0] + 60) & table), 5000);
  EXPECT_GT(cv::countNonZero((channels[0] > 150) & table), 5000);
  std::filesystem::remove_all(dir);
}

TEST(SimRender, TransparentObjectsShowWhatIsBehindThem) {
  // A white bottle in front of a red wall: opaque, its pixels are white; clear, they are pinkish.
  auto mean_colour_of_object = [](double opacity) {
    Scene scene = one_object("bottle", 0.45, 0.0);
    scene.background.colour = Eigen::Vector3d(0.9, 0.1, 0.1);
    scene.objects[0].appearance.opacity = opacity;
    World world(scene);
    const cv::Mat image = world.render(0);
    const cv::Mat mask = world.render_mask(0) == 1;
    EXPECT_GT(cv::countNonZero(mask), 500);
    return cv::mean(image, mask);  // BGR
  };
  const cv::Scalar opaque = mean_colour_of_object(1.0), clear = mean_colour_of_object(0.25);
  EXPECT_NEAR(opaque[2] - opaque[0], 0, 30) << "an opaque white bottle is grey-white";
  EXPECT_GT(clear[2] - clear[0], opaque[2] - opaque[0] + 20) << "a clear one lets the wall's red through";
  EXPECT_NE(load_error("%YAML:1.0\nobjects:\n  - { kind: cup, position: [0.25, 0], opacity: 0 }\n").find("opacity"),
            std::string::npos);
}

TEST(SimRender, PusherCanBeHiddenAndNoiseIsSeeded) {
  Scene scene = one_object("cup");
  scene.render.noise_sigma = 3;
  World a(scene), b(scene);
  const cv::Mat ia = a.render(1), ib = b.render(1);
  EXPECT_EQ(cv::norm(ia, ib, cv::NORM_INF), 0);  // same seed, same noise
  EXPECT_GT(cv::norm(ia, a.render(1), cv::NORM_L1), 0);  // fresh noise each frame
  // The pad in front of the cup occludes it in the mask unless hidden.
  World w(one_object("cup"));
  const int visible = cv::countNonZero(w.render_mask(1) == 1);
  w.set_pusher(Eigen::Vector3d(0.35, 0.0, 0.05), M_PI);
  w.step();
  const int occluded = cv::countNonZero(w.render_mask(1) == 1);
  w.pusher_visible = false;
  const int hidden = cv::countNonZero(w.render_mask(1) == 1);
  EXPECT_LT(occluded, visible - 300);
  EXPECT_NEAR(hidden, visible, 5);  // the cup may have settled by a hair in the step
}

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

TEST(SimPhysics, PushStartingInsideAnObjectIsRefused) {
  World world(one_object("cup"));
  EXPECT_THROW(world.push(Eigen::Vector3d(0.25, -0.02, 0.03), Eigen::Vector3d(0.25, 0.05, 0.03)),
               SimError);
  EXPECT_FALSE(world.pusher_in_contact());
}

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

void expect_lift_turn_place(const LiftTurnPlace& r, double bottle_diameter) {
  EXPECT_NEAR(r.closed_opening, bottle_diameter, 0.005) << "the fingers stop on the bottle";
  EXPECT_TRUE(r.held_throughout);
  EXPECT_NEAR(r.lift, 0.05, 0.003);
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

TEST(SimArm, TheSimulatedArmNudgesACupAcrossTheTable) {
  // The thesis' nudge (fig. 6.3-6.4) planned by the robot library and played on the simulated
  // arm's servos, the pad mounted on its flange: the cup slides a few centimetres, upright.
  namespace robot = nudge::robot;
  Scene scene = with_arm(one_object("cup", 0.25, 0.0));
  World world(scene);
  world.mount_tools_on_arm(0.15);
  const robot::ArmModel puma = robot::puma260();
  robot::SafetyConfig safety;
  safety.table_z = -scene.arm.shoulder_height;
  const robot::IkResult home = robot::home_configuration(puma, safety);
  ASSERT_TRUE(home.ok()) << home.reason;
  const robot::NudgePlan plan =
      robot::plan_nudge(puma, safety, Eigen::Vector3d(0.25, 0.0, safety.table_z), Eigen::Vector3d(0, 1, 0),
                        robot::NudgeParams{}, home.q);
  ASSERT_TRUE(plan.ok()) << plan.reason;
  auto as_array = [](const robot::JointVector& q) {
    std::array<double, 6> a;
    for (int j = 0; j < 6; ++j) a[j] = q[j];
    return a;
  };
  // Home first, then the planned path at no more than 0.5 deg per 10 ms.
  world.set_arm_joints(as_array(home.q));
  world.step_for(0.5);
  const Eigen::Vector3d before = world.object(0).position;
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
  const ObjectState after = world.object(0);
  const double moved = (after.position - before).head<2>().norm();
  EXPECT_GT(moved, 0.01) << "the cup moved 1-3 cm";
  EXPECT_LT(moved, 0.03) << "the cup moved 1-3 cm";
  EXPECT_GT(after.position.y() - before.y(), 0.004) << "along the push direction";
  EXPECT_LT(after.tilt(), 5 * kDeg) << "and stayed upright";
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
