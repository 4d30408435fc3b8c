// The verged stereo rig, its ground truth and its lens distortion.
#include "sim_test_helpers.hpp"


using namespace nudge::sim;
using namespace nudge::sim::test;

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
  EXPECT_DOUBLE_EQ(l.lens.K(0, 2), 319.5);
  EXPECT_DOUBLE_EQ(l.lens.K(1, 2), 239.5);
  EXPECT_NEAR(l.lens.K(1, 1), 240 / std::tan(22.5 * kDeg), 1e-9);
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
  ideal.lens.distortion = {};
  EXPECT_EQ(pinhole_canvas(ideal).width, 640);
}

// The geometry rig a sim rig calibrates to sees a world point where the sim cameras do: the left
// lens projects the point in the left camera's frame, the right lens the point carried over by the
// rig's extrinsics.
void expect_calibrated_rig_matches(const RigSpec& spec) {
  const StereoRig sim_rig = make_rig(spec);
  const nudge::geometry::StereoRig rig = sim_rig.calibrated();
  const CameraModel& l = sim_rig.cameras[0];
  const CameraModel& r = sim_rig.cameras[1];
  EXPECT_EQ(rig.left.width, l.lens.width);
  EXPECT_EQ(rig.right.height, r.lens.height);
  EXPECT_LT((rig.R - sim_rig.R_right_left()).norm(), 1e-12);
  EXPECT_LT((rig.T - sim_rig.t_right_left()).norm(), 1e-12);
  for (const Eigen::Vector3d& X : {Eigen::Vector3d(0.25, 0, 0.06), Eigen::Vector3d(0.1, 0.3, 0.0),
                                  Eigen::Vector3d(0.4, -0.25, 0.2)}) {
    const Eigen::Vector3d in_left = l.to_camera(X);
    EXPECT_LT((rig.left_to_right(in_left) - r.to_camera(X)).norm(), 1e-12);
    EXPECT_LT((rig.left.project(in_left) - l.project(X)).norm(), 1e-9);
    EXPECT_LT((rig.right.project(rig.left_to_right(in_left)) - r.project(X)).norm(), 1e-9);
  }
}

TEST(SimCamera, CalibratedRigProjectsLikeTheSimCameras) {
  RigSpec spec;
  expect_calibrated_rig_matches(spec);
  spec.distortion = {-0.25, 0.1, 0.001, -0.002, 0.01};
  expect_calibrated_rig_matches(spec);
}

TEST(SimCamera, UndistortNamesTheCameraWhereTheLensFoldsOver) {
  RigSpec spec;
  spec.distortion = {-0.5, 0, 0, 0, 0};
  const CameraModel cam = make_rig(spec).cameras[0];
  try {
    cam.undistort(Eigen::Vector2d(-5000, -5000));
    FAIL() << "expected std::domain_error";
  } catch (const std::domain_error& e) {
    EXPECT_NE(std::string(e.what()).find("camera 'left'"), std::string::npos) << e.what();
  }
}

// With lens distortion the renderer warps a larger pinhole image: silhouettes still land where
// the distorted camera model projects them, and the corners are filled.
