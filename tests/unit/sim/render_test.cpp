// Offscreen rendering: stereo pairs, masks, intrinsics, distortion, textures, noise.
#include "sim_test_helpers.hpp"

#include <filesystem>

using namespace nudge::sim;
using namespace nudge::sim::test;

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
