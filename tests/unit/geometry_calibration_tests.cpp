// Unit tests of absolute orientation (Arun et al. 1987) for the camera-arm calibration (thesis
// App. B). Registered by hand in tests/CMakeLists.txt, linked with nudge_geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "nudge/geometry/absolute_orientation.hpp"

namespace geo = nudge::geometry;

namespace {

constexpr double kDeg = M_PI / 180.0;

geo::RigidTransform some_motion() {
  geo::RigidTransform m;
  m.R = (Eigen::AngleAxisd(130 * kDeg, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(-120 * kDeg, Eigen::Vector3d::UnitX()) *
         Eigen::AngleAxisd(7 * kDeg, Eigen::Vector3d::UnitY()))
            .toRotationMatrix();
  m.t = {0.12, -0.31, 0.68};
  return m;
}

// Corners of a 9 x 6 board with 25 mm squares lying on the table (z = 0): coplanar points.
std::vector<Eigen::Vector3d> board_on_table() {
  std::vector<Eigen::Vector3d> points;
  for (int r = 0; r < 6; ++r)
    for (int c = 0; c < 9; ++c) points.emplace_back(0.15 + 0.025 * r, -0.1 + 0.025 * c, 0.0);
  return points;
}

}  // namespace

TEST(AbsoluteOrientation, RecoversAKnownMotionFromCoplanarPointsExactly) {
  const geo::RigidTransform truth = some_motion();
  const auto from = board_on_table();
  std::vector<Eigen::Vector3d> to;
  for (const auto& p : from) to.push_back(truth.apply(p));
  const auto fit = geo::absolute_orientation(from, to);
  ASSERT_TRUE(fit) << fit.reason();
  EXPECT_NEAR(fit->transform.R.determinant(), 1.0, 1e-12) << "a rotation, not a reflection";
  EXPECT_LT(geo::rotation_angle_between(fit->transform.R, truth.R), 1e-9);
  EXPECT_LT((fit->transform.t - truth.t).norm(), 1e-12);
  EXPECT_LT(fit->rms_residual, 1e-12);
  // The inverse maps back.
  EXPECT_LT((fit->transform.inverse().apply(to[7]) - from[7]).norm(), 1e-12);
}

TEST(AbsoluteOrientation, NoisyPointsGiveAnErrorOfTheOrderOfTheNoiseOverTheirSpread) {
  const geo::RigidTransform truth = some_motion();
  std::vector<Eigen::Vector3d> from = board_on_table(), to;
  for (const auto& p : board_on_table()) from.push_back(p + Eigen::Vector3d(0.2, 0.05, 0.0));  // two board poses
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, 0.0005);  // 0.5 mm, about what stereo gives at 0.7 m
  for (const auto& p : from) to.push_back(truth.apply(p) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  const auto fit = geo::absolute_orientation(from, to);
  ASSERT_TRUE(fit) << fit.reason();
  EXPECT_NEAR(fit->transform.R.determinant(), 1.0, 1e-12);
  EXPECT_LT(geo::rotation_angle_between(fit->transform.R, truth.R), 0.1 * kDeg);
  // The arm base (the origin of `from`) lands within a millimetre.
  EXPECT_LT((fit->transform.apply(Eigen::Vector3d::Zero()) - truth.t).norm(), 0.001);
  EXPECT_NEAR(fit->rms_residual, 0.0005 * std::sqrt(3.0), 0.0003);
}

TEST(AbsoluteOrientation, DegenerateInputFailsWithAReason) {
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_FALSE(geo::absolute_orientation(two, two));
  const std::vector<Eigen::Vector3d> line = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}};
  const auto collinear = geo::absolute_orientation(line, line);
  ASSERT_FALSE(collinear);
  EXPECT_NE(collinear.reason().find("one line"), std::string::npos) << collinear.reason();
  std::vector<Eigen::Vector3d> bad = board_on_table();
  bad[3].x() = std::nan("");
  EXPECT_FALSE(geo::absolute_orientation(bad, board_on_table()));
  EXPECT_FALSE(geo::absolute_orientation(board_on_table(), two));
}
