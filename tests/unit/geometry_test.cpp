#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/core/eigen.hpp>  // after Eigen, as OpenCV requires

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include "nudge/geometry/axis_appearance.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/qt_cluster.hpp"
#include "nudge/geometry/self_mask.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/table_texture.hpp"
#include "nudge/geometry/triangulation.hpp"
#include "nudge/geometry/upright.hpp"
#include "nudge/geometry/workspace.hpp"

using namespace nudge::geometry;
namespace sym = nudge::symmetry;

namespace {

constexpr double kDeg = M_PI / 180.0;

Camera make_camera(double f, double cx, double cy, std::array<double, 5> distortion) {
  Camera c;
  c.K << f, 0, cx, 0, f * 1.002, cy, 0, 0, 1;
  c.distortion = distortion;
  return c;
}

// A verged rig like the thesis' (fig. 4.5): 0.25 m baseline, right camera turned 15 deg towards the
// left one and rolled 1 deg about its optical axis (the mounting bracket's error).
// Lens distortion of a typical webcam; `strong` is a wide-angle lens.
enum class Lens { None, Typical, Strong };

StereoRig verged_rig(Lens lens = Lens::Typical) {
  StereoRig rig;
  rig.left = make_camera(620, 322.5, 236.0, {-0.15, 0.07, 0.0012, -0.0008, -0.01});
  rig.right = make_camera(610, 317.0, 243.5, {-0.13, 0.05, -0.0006, 0.0010, 0.0});
  if (lens == Lens::Strong) {
    rig.left.distortion = {-0.25, 0.12, 0.0012, -0.0008, -0.02};
    rig.right.distortion = {-0.22, 0.09, -0.0006, 0.0010, 0.0};
  }
  if (lens == Lens::None) rig.left.distortion = rig.right.distortion = {};
  const Eigen::Matrix3d right_axes_in_left =
      (Eigen::AngleAxisd(-15 * kDeg, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(1 * kDeg, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  const Eigen::Vector3d right_centre_in_left(0.25, 0.005, 0.0);
  rig.R = right_axes_in_left.transpose();
  rig.T = -rig.R * right_centre_in_left;
  return rig;
}

// The table and "up" in the left camera's frame: cameras 0.45 m above the table, pitched 30 deg down.
struct Table {
  double pitch = 30 * kDeg, height = 0.45;
  Eigen::Vector3d up() const { return {0, -std::cos(pitch), -std::sin(pitch)}; }
  Eigen::Vector3d forward() const { return {0, -std::sin(pitch), std::cos(pitch)}; }
  Eigen::Vector3d at(double lateral, double distance) const {
    return lateral * Eigen::Vector3d::UnitX() + distance * forward() - height * up();
  }
};

std::vector<cv::Point2d> project(const std::vector<Eigen::Vector3d>& points, const Camera& camera,
                                 const Eigen::Matrix3d& R, const Eigen::Vector3d& T) {
  std::vector<cv::Point3d> object;
  for (const auto& p : points) object.emplace_back(p.x(), p.y(), p.z());
  cv::Mat rmat, rvec, tvec, K;
  cv::eigen2cv(R, rmat);
  cv::Rodrigues(rmat, rvec);
  cv::eigen2cv(T, tvec);
  cv::eigen2cv(camera.K, K);
  std::vector<cv::Point2d> image;
  cv::projectPoints(object, rvec, tvec, K, std::vector<double>(camera.distortion.begin(), camera.distortion.end()),
                    image);
  return image;
}

// Total-least-squares line through image points, as (R, theta) with theta in (-90, 90] deg; the
// support segment spans the points (what the detector reports).
sym::Line fit_line(const std::vector<cv::Point2d>& points, int width, int height) {
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean *= 1.0 / points.size();
  double sxx = 0, syy = 0, sxy = 0;
  for (const auto& p : points) {
    sxx += (p.x - mean.x) * (p.x - mean.x);
    syy += (p.y - mean.y) * (p.y - mean.y);
    sxy += (p.x - mean.x) * (p.y - mean.y);
  }
  const double along = 0.5 * std::atan2(2 * sxy, sxx - syy);  // principal direction of the points
  Eigen::Vector2d normal(-std::sin(along), std::cos(along));
  double theta = std::atan2(normal.y(), normal.x());
  if (theta <= -M_PI / 2) theta += M_PI, normal = -normal;
  if (theta > M_PI / 2) theta -= M_PI, normal = -normal;
  sym::Line line;
  line.theta = theta;
  line.r = normal.x() * (mean.x - 0.5 * (width - 1)) + normal.y() * (mean.y - 0.5 * (height - 1));
  line.seg1 = points.front();
  line.seg2 = points.back();
  sym::border_endpoints(line.r, line.theta, width, height, &line.end1, &line.end2);
  return line;
}

struct StereoAxis {
  Eigen::Vector3d base, top;  // right camera frame
  sym::Line left, right;
};

StereoAxis observe_axis(const StereoRig& rig, const Table& table, double lateral, double distance, double tall) {
  const Eigen::Vector3d base = table.at(lateral, distance), top = base + tall * table.up();
  std::vector<Eigen::Vector3d> along;
  for (int i = 0; i <= 60; ++i) along.push_back(base + (top - base) * (i / 60.0));
  const auto left_pixels = project(along, rig.left, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const auto right_pixels = project(along, rig.right, rig.R, rig.T);
  for (const auto& p : left_pixels) EXPECT_TRUE(p.inside(cv::Rect2d(0, 0, 639, 479))) << "left view misses the axis";
  for (const auto& p : right_pixels) EXPECT_TRUE(p.inside(cv::Rect2d(0, 0, 639, 479))) << "right view misses the axis";
  return {rig.left_to_right(base), rig.left_to_right(top), fit_line(left_pixels, 640, 480),
          fit_line(right_pixels, 640, 480)};
}

Plane table_plane_in_right(const StereoRig& rig, const Table& table) {
  std::vector<Eigen::Vector3d> corners;  // a checkerboard's corners
  for (int i = 0; i < 7; ++i)
    for (int j = 0; j < 5; ++j) corners.push_back(rig.left_to_right(table.at(-0.1 + 0.05 * i, 0.45 + 0.05 * j)));
  const auto plane = fit_plane(corners);
  EXPECT_TRUE(plane.ok()) << plane.reason();
  return *plane;
}

double angle_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::fabs(a.normalized().dot(b.normalized())))) / kDeg;
}

std::string temp_path(const std::string& name) {
  return (std::filesystem::temp_directory_path() / ("nudge_geometry_test_" + std::to_string(::getpid()) + "_" + name))
      .string();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Lens model

TEST(GeometryCamera, ProjectMatchesOpenCvAndNormaliseInvertsIt) {
  const StereoRig rig = verged_rig();
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> xy(-0.45, 0.45), z(0.4, 2.0);
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p(xy(rng), xy(rng) * 0.75, z(rng));
    const cv::Point2d reference = project({p}, rig.left, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero())[0];
    const Eigen::Vector2d pixel = rig.left.project(p);
    EXPECT_NEAR(pixel.x(), reference.x, 1e-9);
    EXPECT_NEAR(pixel.y(), reference.y, 1e-9);
    const auto normalised = rig.left.normalise(pixel);
    ASSERT_TRUE(normalised.ok()) << normalised.reason();
    EXPECT_NEAR(normalised->x(), p.x() / p.z(), 1e-10);
    EXPECT_NEAR(normalised->y(), p.y() / p.z(), 1e-10);
  }
}

TEST(GeometryCamera, ImageCornersUndistort) {
  const StereoRig rig = verged_rig();
  for (const Eigen::Vector2d& corner : {Eigen::Vector2d(0, 0), Eigen::Vector2d(639, 0), Eigen::Vector2d(0, 479),
                                       Eigen::Vector2d(639, 479)}) {
    const auto n = rig.left.normalise(corner);
    ASSERT_TRUE(n.ok()) << n.reason();
    EXPECT_NEAR((rig.left.project(Eigen::Vector3d(n->x(), n->y(), 1)) - corner).norm(), 0, 1e-8);
  }
}

// ---------------------------------------------------------------------------------------------
// Triangulation

TEST(GeometryTriangulation, LineEndpointsFollowEq41To43) {
  const auto vertical = line_endpoints(10, 0, 640, 480);
  ASSERT_TRUE(vertical.ok());
  EXPECT_NEAR(vertical->first.x(), 329.5, 1e-9);
  EXPECT_NEAR(vertical->second.x(), 329.5, 1e-9);
  EXPECT_NEAR(std::fabs(vertical->first.y() - vertical->second.y()), 479, 1e-9);
  // A tilted line: both ends on the line (eq. 4.1) and on the image border.
  const double r = 50, theta = 30 * kDeg;
  const auto tilted = line_endpoints(r, theta, 640, 480);
  ASSERT_TRUE(tilted.ok());
  for (const Eigen::Vector2d& p : {tilted->first, tilted->second}) {
    EXPECT_NEAR(std::cos(theta) * (p.x() - 319.5) + std::sin(theta) * (p.y() - 239.5), r, 1e-9);
    const double to_border = std::min({p.x(), p.y(), 639 - p.x(), 479 - p.y()});
    EXPECT_NEAR(to_border, 0, 1e-9);
  }
  const auto missing = line_endpoints(1000, 0.1, 640, 480);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.reason().find("misses"), std::string::npos) << missing.reason();
}

TEST(GeometryTriangulation, RecoversKnownAxesThroughDistortedVergedRig) {
  const StereoRig rig = verged_rig();
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  int checked = 0;
  for (double lateral : {0.0, 0.08, 0.16}) {
    for (double distance : {0.5, 0.65, 0.8}) {
      SCOPED_TRACE("lateral " + std::to_string(lateral) + " distance " + std::to_string(distance));
      const StereoAxis truth = observe_axis(rig, table, lateral, distance, 0.18);
      const auto axis = triangulate_axis(rig, truth.left, truth.right);
      ASSERT_TRUE(axis.ok()) << axis.reason();
      const auto hit = check_axis(*axis, plane);
      ASSERT_TRUE(hit.ok()) << hit.reason();
      EXPECT_LT((hit->point - truth.base).norm(), 0.0005);
      EXPECT_LT(angle_deg(axis->direction(), truth.top - truth.base), 0.2);
      EXPECT_LT(hit->tilt_deg, 0.2);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 9);
}

TEST(GeometryTriangulation, ThesisEndpointPlaneIsExactWithoutDistortion) {
  const StereoRig rig = verged_rig(Lens::None);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  TriangulationParams thesis;
  thesis.plane_samples = 0;
  const StereoAxis truth = observe_axis(rig, table, 0.1, 0.6, 0.15);
  const auto axis = triangulate_axis(rig, truth.left, truth.right, thesis);
  ASSERT_TRUE(axis.ok()) << axis.reason();
  EXPECT_LT((intersect_axis_plane(*axis, plane).value() - truth.base).norm(), 1e-6);
  // The segment lies inside both triangles: no deeper than zmax in the right camera.
  EXPECT_LE(std::max(axis->a.z(), axis->b.z()), thesis.zmax + 1e-9);
}

TEST(GeometryTriangulation, FittedPlaneCorrectsWhatBorderEndpointsMissUnderStrongDistortion) {
  // The image of a straight axis is curved; a straight (R, theta) fit drifts from it towards the
  // border, where the thesis takes its two end points. Sampling the support segment does not.
  const StereoRig rig = verged_rig(Lens::Strong);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  TriangulationParams thesis;
  thesis.plane_samples = 0;
  double worst_fitted = 0, worst_thesis = 0;
  for (double lateral : {0.0, 0.16}) {
    for (double distance : {0.5, 0.8}) {
      const StereoAxis truth = observe_axis(rig, table, lateral, distance, 0.18);
      const auto fitted = triangulate_axis(rig, truth.left, truth.right);
      const auto endpoints = triangulate_axis(rig, truth.left, truth.right, thesis);
      ASSERT_TRUE(fitted.ok() && endpoints.ok());
      worst_fitted = std::max(worst_fitted, (intersect_axis_plane(*fitted, plane).value() - truth.base).norm());
      worst_thesis = std::max(worst_thesis, (intersect_axis_plane(*endpoints, plane).value() - truth.base).norm());
    }
  }
  EXPECT_LT(worst_fitted, 0.001);
  EXPECT_LT(worst_fitted * 5, worst_thesis);
}

TEST(GeometryTriangulation, BackProjectedTriangleReachesZmaxAlongTheEndRays) {
  // eq. 4.4: the triangle is the focal point and the two end points' rays, each cut at depth zmax.
  const StereoRig rig = verged_rig(Lens::None);
  sym::Line line;
  line.r = 60;
  line.theta = 25 * M_PI / 180;  // tilted: its two ends lie at different depths along their rays
  TriangulationParams params;
  params.plane_samples = 0;
  const auto triangle = backproject_line(rig.left, line, params);
  ASSERT_TRUE(triangle.ok()) << triangle.reason();
  EXPECT_LT(triangle->a.norm(), 1e-12);
  EXPECT_NEAR(triangle->b.z(), params.zmax, 1e-9);
  EXPECT_NEAR(triangle->c.z(), params.zmax, 1e-9);
  const auto ends = line_endpoints(line.r, line.theta, rig.left.width, rig.left.height);
  ASSERT_TRUE(ends.ok());
  const Eigen::Vector2d n1 = rig.left.normalise(ends->first).value(), n2 = rig.left.normalise(ends->second).value();
  EXPECT_LT((triangle->b - params.zmax * Eigen::Vector3d(n1.x(), n1.y(), 1)).norm(), 1e-9);
  EXPECT_LT((triangle->c - params.zmax * Eigen::Vector3d(n2.x(), n2.y(), 1)).norm(), 1e-9);
}

TEST(GeometryTriangulation, TriangleIntersectionOfKnownTriangles) {
  // Two triangles crossing along the x axis, overlapping on [0, 1] there.
  const Triangle horizontal{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}};  // z = 0, covers x in [-1, 1] at y = 0
  const Triangle vertical{{0, 0, -1}, {3, 0, -1}, {0, 0, 1}};     // y = 0, covers x in [0, 1.5] at z = 0
  const auto segment = intersect_triangles(horizontal, vertical);
  ASSERT_TRUE(segment.ok()) << segment.reason();
  const double lo = std::min(segment->a.x(), segment->b.x()), hi = std::max(segment->a.x(), segment->b.x());
  EXPECT_NEAR(lo, 0.0, 1e-12);
  EXPECT_NEAR(hi, 1.0, 1e-12);
  EXPECT_NEAR(segment->a.y(), 0, 1e-12);
  EXPECT_NEAR(segment->a.z(), 0, 1e-12);

  const Triangle far_away{{5, 0, -1}, {6, 0, -1}, {5, 0, 1}};  // same plane as `vertical`, beyond x = 1
  EXPECT_FALSE(intersect_triangles(horizontal, far_away).ok());
  const Triangle above{{-1, -1, 1}, {1, -1, 1}, {1, 1, 2}};
  const auto miss = intersect_triangles(horizontal, above);
  ASSERT_FALSE(miss.ok());
  EXPECT_NE(miss.reason().find("do not intersect"), std::string::npos) << miss.reason();
  const Triangle degenerate{{0, 0, 0}, {1, 1, 1}, {2, 2, 2}};
  EXPECT_NE(intersect_triangles(horizontal, degenerate).reason().find("degenerate"), std::string::npos);
}

TEST(GeometryTriangulation, DegenerateCasesGiveReasonsNotNaN) {
  StereoRig rig = verged_rig(Lens::None);
  const Table table;
  const StereoAxis truth = observe_axis(rig, table, 0.05, 0.6, 0.15);

  StereoRig same_centre = rig;
  same_centre.T.setZero();
  auto axis = triangulate_axis(same_centre, truth.left, truth.right);
  ASSERT_FALSE(axis.ok());
  EXPECT_NE(axis.reason().find("camera centres coincide"), std::string::npos) << axis.reason();

  sym::Line off_image = truth.left;
  off_image.r = 5000;
  axis = triangulate_axis(rig, off_image, truth.right);
  ASSERT_FALSE(axis.ok());
  EXPECT_NE(axis.reason().find("left line"), std::string::npos) << axis.reason();
  EXPECT_NE(axis.reason().find("misses"), std::string::npos) << axis.reason();

  // A rectified rig: both horizontal lines through the principal point lie in the epipolar plane.
  StereoRig rectified;
  rectified.left = rectified.right = make_camera(600, 319.5, 239.5, {});
  rectified.right.K(1, 1) = 600;
  rectified.left.K(1, 1) = 600;
  rectified.T = Eigen::Vector3d(-0.2, 0, 0);
  sym::Line horizontal;
  horizontal.theta = 90 * kDeg;
  axis = triangulate_axis(rectified, horizontal, horizontal);
  ASSERT_FALSE(axis.ok());
  EXPECT_NE(axis.reason().find("parallel"), std::string::npos) << axis.reason();

  // Lines whose back-projections only meet behind the cameras or beyond zmax.
  sym::Line far_left, far_right;
  far_left.r = -300;   // left camera looks far left...
  far_right.r = 300;   // ...right camera far right: the planes diverge
  axis = triangulate_axis(rectified, far_left, far_right);
  ASSERT_FALSE(axis.ok());
  EXPECT_FALSE(axis.reason().empty());

  TriangulationParams bad;
  bad.zmax = std::nan("");
  EXPECT_FALSE(triangulate_axis(rig, truth.left, truth.right, bad).ok());
  bad = TriangulationParams{};
  bad.plane_samples = 2;
  EXPECT_FALSE(triangulate_axis(rig, truth.left, truth.right, bad).ok());
}

// ---------------------------------------------------------------------------------------------
// Table plane and filters

TEST(GeometryPlane, FitsNoisyPointsAndOrientsTowardsCamera) {
  const Table table;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0, 0.0005);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 50; ++i)
    points.push_back(table.at(-0.2 + 0.01 * i, 0.4 + 0.05 * (i % 7)) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng)));
  const auto plane = fit_plane(points);
  ASSERT_TRUE(plane.ok()) << plane.reason();
  EXPECT_LT(angle_deg(plane->normal, table.up()), 0.5);
  EXPECT_GT(plane->normal.dot(table.up()), 0);  // the camera is above the table
  EXPECT_NEAR(plane->offset, table.height, 0.002);
  EXPECT_LT(plane->rms_residual, 0.001);

  EXPECT_FALSE(fit_plane({}).ok());
  const auto collinear = fit_plane({{0, 0, 1}, {0.1, 0, 1}, {0.2, 0, 1}, {0.3, 0, 1}});
  ASSERT_FALSE(collinear.ok());
  EXPECT_NE(collinear.reason().find("collinear"), std::string::npos);
  EXPECT_FALSE(fit_plane({{0, 0, 1}, {0, 1, 1}, {std::nan(""), 0, 1}}).ok());
}

TEST(GeometryPlane, AxisFiltersGiveReasons) {
  Plane table;  // z = -0.5 seen from the origin above: normal +z, offset 0.5
  table.normal = Eigen::Vector3d::UnitZ();
  table.offset = 0.5;
  const Segment3 upright{{0.3, 0.2, -0.5}, {0.3, 0.2, -0.3}};
  auto hit = check_axis(upright, table);
  ASSERT_TRUE(hit.ok()) << hit.reason();
  EXPECT_NEAR((hit->point - Eigen::Vector3d(0.3, 0.2, -0.5)).norm(), 0, 1e-12);
  EXPECT_NEAR(hit->tilt_deg, 0, 1e-9);

  const double lean = std::tan(20 * kDeg) * 0.2;
  hit = check_axis({{0.3, 0.2, -0.5}, {0.3 + lean, 0.2, -0.3}}, table);
  ASSERT_FALSE(hit.ok());
  EXPECT_NE(hit.reason().find("tilted 20.0 deg"), std::string::npos) << hit.reason();
  AxisFilter loose;
  loose.max_tilt_deg = 25;
  EXPECT_TRUE(check_axis({{0.3, 0.2, -0.5}, {0.3 + lean, 0.2, -0.3}}, table, loose).ok());

  hit = check_axis({{3, 0, -0.5}, {3, 0, -0.3}}, table);
  ASSERT_FALSE(hit.ok());
  EXPECT_NE(hit.reason().find("from the camera"), std::string::npos) << hit.reason();

  hit = check_axis({{0, 0, -0.4}, {1, 0, -0.4}}, table);  // lying flat
  ASSERT_FALSE(hit.ok());
  EXPECT_NE(hit.reason().find("parallel"), std::string::npos) << hit.reason();

  AxisFilter ring;
  ring.ring_centre = Eigen::Vector3d(0.3, 0.0, -0.5);
  EXPECT_TRUE(check_axis(upright, table, ring).ok());  // 200 mm from the base
  ring.ring_centre = Eigen::Vector3d(0.3, 0.15, -0.5);
  hit = check_axis(upright, table, ring);  // 50 mm from the base
  ASSERT_FALSE(hit.ok());
  EXPECT_NE(hit.reason().find("workspace ring"), std::string::npos) << hit.reason();

  EXPECT_FALSE(check_axis(Segment3{}, table).ok());
}

TEST(GeometryPlane, PlaneFrameRoundTrip) {
  const Table table;
  const auto plane = fit_plane({table.at(0, 0.5), table.at(0.2, 0.5), table.at(0, 0.8), table.at(0.3, 0.9)});
  ASSERT_TRUE(plane.ok());
  const PlaneFrame frame(*plane);
  const Eigen::Vector3d p = table.at(0.12, 0.66);
  EXPECT_NEAR((frame.to_space(frame.to_plane(p)) - p).norm(), 0, 1e-12);
  EXPECT_NEAR((frame.to_plane(table.at(0.1, 0.5)) - frame.to_plane(table.at(0.0, 0.5))).norm(), 0.1, 1e-12);
}

// ---------------------------------------------------------------------------------------------
// QT clustering

TEST(GeometryQt, FindsClustersAndRejectsSmallOnes) {
  std::mt19937 rng(3);
  std::normal_distribution<double> jitter(0, 0.002);
  const std::vector<Eigen::Vector2d> centres = {{0.10, 0.20}, {0.25, 0.22}, {0.18, 0.35}};
  const std::vector<int> sizes = {30, 20, 12};
  std::vector<Eigen::Vector2d> points;
  for (size_t c = 0; c < centres.size(); ++c)
    for (int i = 0; i < sizes[c]; ++i) points.push_back(centres[c] + Eigen::Vector2d(jitter(rng), jitter(rng)));
  std::uniform_real_distribution<double> anywhere(-0.5, 0.5);
  for (int i = 0; i < 10; ++i) points.push_back(Eigen::Vector2d(0.8, 0.8) + Eigen::Vector2d(anywhere(rng), anywhere(rng)) * 0.4);
  // 72 points: minimum cluster size 8; the scattered points never gather 8 within 10 mm.
  const std::vector<Cluster> clusters = qt_cluster(points);
  ASSERT_EQ(clusters.size(), 3u);
  for (size_t c = 0; c < 3; ++c) {
    EXPECT_LT((clusters[c].centroid - centres[c]).norm(), 0.0015) << "cluster " << c;
    EXPECT_GE(clusters[c].size(), sizes[c] - 2);
    EXPECT_LE(clusters[c].size(), sizes[c]);
    for (int i : clusters[c].members) EXPECT_LE((points[i] - clusters[c].centroid).norm(), 0.02);
  }
  QtParams one;
  one.max_clusters = 1;
  EXPECT_EQ(qt_cluster(points, one).size(), 1u);
}

TEST(GeometryQt, ExactSmallSets) {
  // Points on a line 6 mm apart: seeds in the middle reach both neighbours (12 mm apart from each
  // other, but each within 10 mm of the seed), so clusters of 3 form.
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 6; ++i) points.push_back({0.006 * i, 0});
  QtParams params;
  params.min_fraction = 0;
  const auto clusters = qt_cluster(points, params);
  ASSERT_EQ(clusters.size(), 2u);
  EXPECT_EQ(clusters[0].members, (std::vector<int>{0, 1, 2}));  // seeds 1-4 tie: lowest seed index first
  EXPECT_NEAR(clusters[0].centroid.x(), 0.006, 1e-12);
  EXPECT_EQ(clusters[1].members, (std::vector<int>{3, 4, 5}));
  EXPECT_NEAR(clusters[1].centroid.x(), 0.024, 1e-12);

  EXPECT_TRUE(qt_cluster({}).empty());
  params.min_fraction = 0.5;  // 3 of 6 points: still enough
  EXPECT_EQ(qt_cluster(points, params).size(), 2u);
  params.min_fraction = 0.51;
  EXPECT_TRUE(qt_cluster(points, params).empty());
  // Thesis default: at least 1/9 of all points. A lone point among 9 is a cluster, among 10 it is not.
  std::vector<Eigen::Vector2d> ten(9, Eigen::Vector2d(0, 0));
  ten.push_back({1, 1});
  const auto default_clusters = qt_cluster(ten);
  ASSERT_EQ(default_clusters.size(), 1u);
  EXPECT_EQ(default_clusters[0].size(), 9);
  ten.pop_back();
  ten.push_back({1, 1});
  ten.erase(ten.begin());  // 8 at the origin, 1 far away: 9 points, min size 1
  EXPECT_EQ(qt_cluster(ten).size(), 2u);
}

TEST(GeometryQt, InvalidParams) {
  QtParams bad;
  bad.radius = 0;
  EXPECT_THROW(qt_cluster({{0, 0}}, bad), std::invalid_argument);
  bad = QtParams{};
  bad.min_fraction = 2;
  EXPECT_THROW(qt_cluster({{0, 0}}, bad), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Rig file

TEST(GeometryRig, YamlRoundTrip) {
  const StereoRig rig = verged_rig();
  const std::string path = temp_path("rig.yaml");
  save_rig(rig, path);
  const StereoRig back = load_rig(path);
  EXPECT_EQ(back.left.width, 640);
  EXPECT_EQ(back.right.height, 480);
  EXPECT_LT((back.left.K - rig.left.K).norm(), 1e-12);
  EXPECT_LT((back.right.K - rig.right.K).norm(), 1e-12);
  for (int i = 0; i < 5; ++i) {
    EXPECT_DOUBLE_EQ(back.left.distortion[i], rig.left.distortion[i]);
    EXPECT_DOUBLE_EQ(back.right.distortion[i], rig.right.distortion[i]);
  }
  EXPECT_LT((back.R - rig.R).norm(), 1e-12);
  EXPECT_LT((back.T - rig.T).norm(), 1e-12);
  std::filesystem::remove(path);
}

TEST(GeometryRig, MissingOrBadFieldNamesFieldAndFile) {
  const std::string path = temp_path("partial.yaml");
  save_rig(verged_rig(), path);
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  in.close();
  const std::string full = text.str();

  // Drop the T matrix (its block runs to the end of the file).
  const std::string without_t = full.substr(0, full.find("\nT:")) + "\n";
  {
    std::ofstream(path) << without_t;
  }
  try {
    load_rig(path);
    FAIL() << "missing T accepted";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(path), std::string::npos) << what;
    EXPECT_NE(what.find("'T'"), std::string::npos) << what;
    EXPECT_NE(what.find("missing"), std::string::npos) << what;
  }

  // Rename a nested field.
  std::string renamed = full;
  renamed.replace(renamed.find("camera_matrix"), 13, "camera_matrixx");
  {
    std::ofstream(path) << renamed;
  }
  try {
    load_rig(path);
    FAIL() << "missing left.camera_matrix accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("left.camera_matrix"), std::string::npos) << e.what();
  }

  EXPECT_THROW(load_rig(temp_path("does_not_exist.yaml")), std::runtime_error);
  {
    std::ofstream(path) << "%YAML:1.0\n---\nleft: [ unterminated\n";
  }
  EXPECT_THROW(load_rig(path), std::runtime_error);
  StereoRig bad = verged_rig();
  bad.R(0, 0) = 2;
  EXPECT_THROW(save_rig(bad, path), std::invalid_argument);
  std::filesystem::remove(path);
}

// The rig files are OpenCV's: what save_rig writes reads back in cv::FileStorage, and a file
// OpenCV writes (the shipped calibration) reads the same through load_rig's yaml-cpp.
TEST(GeometryRig, FilesStayOpenCVs) {
  const StereoRig rig = verged_rig();
  const std::string path = temp_path("opencv.yaml");
  save_rig(rig, path);
  cv::FileStorage fs(path, cv::FileStorage::READ);
  cv::Mat K;
  fs["left"]["camera_matrix"] >> K;
  Eigen::Matrix3d k;
  cv::cv2eigen(K, k);
  EXPECT_LT((k - rig.left.K).norm(), 1e-12);
  EXPECT_EQ(static_cast<int>(fs["right"]["image_width"]), 640);
  fs.release();
  std::filesystem::remove(path);

  const std::string shipped = std::string(NUDGE_SOURCE_DIR) + "/config/calibration_sim.yaml";
  const StereoRig loaded = load_rig(shipped);
  cv::FileStorage opencv(shipped, cv::FileStorage::READ);
  cv::Mat R;
  opencv["R"] >> R;
  Eigen::Matrix3d r;
  cv::cv2eigen(R, r);
  EXPECT_EQ((loaded.R - r).norm(), 0.0);
}

TEST(GeometryRig, MalformedFilesAreRefusedNamingFileAndField) {
  const std::string path = temp_path("malformed.yaml");
  const auto error = [&](const std::string& text) {
    std::ofstream(path) << text;
    try {
      load_rig(path);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("(loaded)");
  };
  // cv::FileStorage, which read rigs before, looped for ever on this one (found by fuzz_workspace).
  std::string what = error("%YAML:1.0\n---a%YAML:1.0\n-#e \n --\nr flagstool_l#en The a");
  EXPECT_EQ(what, path + ": field 'left.image_width' is missing");
  save_rig(verged_rig(), path);
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  const std::string full = text.str();
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string changed = full;
    changed.replace(changed.find(from), from.size(), to);
    return changed;
  };
  what = error(with("rows: 3", "rows: 100000"));
  EXPECT_NE(what.find("'left.camera_matrix' declares 100000x3"), std::string::npos) << what;
  what = error(with("dt: d", "dt: 3d"));
  EXPECT_NE(what.find("'left.camera_matrix.dt'"), std::string::npos) << what;
  what = error(with("data: [", "data: [ 1.,"));
  EXPECT_NE(what.find("'left.camera_matrix.data' must be a list of 9 numbers"), std::string::npos) << what;
  what = error(with("image_width: 640", "image_width: [640"));
  EXPECT_EQ(what.rfind(path + ": not a valid stereo rig file: line", 0), 0u) << what;
  std::filesystem::remove(path);
}

// ---------------------------------------------------------------------------------------------
// Stereo consistency of CANDIDATES (issue 14)

TEST(GeometryStereoCheck, SupportHeightsSpanTheObject) {
  const StereoRig rig = verged_rig(Lens::None);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis a = observe_axis(rig, table, -0.05, 0.6, 0.12);
  const auto axis = triangulate_axis(rig, a.left, a.right);
  ASSERT_TRUE(axis.ok()) << axis.reason();
  const auto hit = check_axis(*axis, plane);
  ASSERT_TRUE(hit.ok()) << hit.reason();
  for (Side side : {Side::Left, Side::Right}) {
    const auto h = support_heights(rig, side, side == Side::Left ? a.left : a.right, *axis, *hit, plane);
    ASSERT_TRUE(h.ok()) << h.reason();
    EXPECT_NEAR(h->low, 0.0, 0.005);
    EXPECT_NEAR(h->high, 0.12, 0.005);
  }
}

TEST(GeometryStereoCheck, KeepsEachObjectsOwnPairingAndDropsFloatingSupport) {
  const StereoRig rig = verged_rig(Lens::None);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis a = observe_axis(rig, table, -0.06, 0.6, 0.10), b = observe_axis(rig, table, 0.05, 0.62, 0.22);
  // The right image lists the objects the other way round: pairing by rank would mix them.
  const std::vector<sym::Line> left = {a.left, b.left}, right = {b.right, a.right};
  const PairingResult all = triangulate_pairings(rig, left, right, &plane);
  LocationParams params;
  params.stereo_check = true;
  const std::vector<PairedAxis> kept = consistent_pairings(rig, left, right, all, plane, params);
  ASSERT_EQ(kept.size(), 2u);
  for (const PairedAxis& p : kept) {
    EXPECT_EQ(p.left_index, 1 - p.right_index);  // a with a, b with b
    const Eigen::Vector3d truth = p.left_index == 0 ? a.base : b.base;
    EXPECT_LT((p.hit->point - truth).norm(), 0.01);
  }
  // Support that starts high above the table (a line through something standing on the objects,
  // or between the tops of two of them) is no object standing on the table.
  std::vector<sym::Line> high_left = left, high_right = right;
  for (sym::Line* l : {&high_left[1], &high_right[0]}) l->seg1 = l->seg1 + 0.6 * (l->seg2 - l->seg1);
  const std::vector<PairedAxis> only_a = consistent_pairings(
      rig, high_left, high_right, triangulate_pairings(rig, high_left, high_right, &plane), plane, params);
  ASSERT_EQ(only_a.size(), 1u);
  EXPECT_EQ(only_a[0].left_index, 0);
}

TEST(GeometryStereoCheck, LocationFinderUsesItOnlyWhenAsked) {
  const StereoRig rig = verged_rig(Lens::None);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis a = observe_axis(rig, table, -0.06, 0.6, 0.10), b = observe_axis(rig, table, 0.05, 0.62, 0.22);
  LocationParams params;
  params.frames = 1;
  params.lines_per_image = 2;
  LocationFinder thesis(rig, plane, std::nullopt, params);
  const int every = thesis.add_frame({a.left, b.left}, {b.right, a.right});
  params.stereo_check = true;
  LocationFinder checked(rig, plane, std::nullopt, params);
  EXPECT_EQ(checked.add_frame({a.left, b.left}, {b.right, a.right}), 2);
  EXPECT_GE(every, 2);
  params.min_height_overlap = 1.5;
  EXPECT_THROW(LocationFinder(rig, plane, std::nullopt, params), std::invalid_argument);
}

// Several objects, one already explored: its lines would be the strongest in every later survey.
// Left out, the one line taken per image is the other object's.
TEST(GeometryLocations, AnExploredObjectsLinesAreLeftOutOfTheStrongest) {
  const StereoRig rig = verged_rig(Lens::Typical);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis explored = observe_axis(rig, table, -0.06, 0.6, 0.15), other = observe_axis(rig, table, 0.07, 0.63, 0.10);
  for (Side side : {Side::Left, Side::Right}) {
    const sym::Line& own = side == Side::Left ? explored.left : explored.right;
    const sym::Line& not_own = side == Side::Left ? other.left : other.right;
    EXPECT_TRUE(is_image_of_upright_axis(rig, side, plane, own, explored.base, 2.0));
    EXPECT_FALSE(is_image_of_upright_axis(rig, side, plane, not_own, explored.base, 8.0));
    // 1 cm off across the view is about 12 px at 0.6 m: outside a 5 px tolerance, inside 20 px.
    const Eigen::Vector3d off = explored.base + 0.01 * Eigen::Vector3d::UnitX();
    EXPECT_FALSE(is_image_of_upright_axis(rig, side, plane, own, off, 5.0));
    EXPECT_TRUE(is_image_of_upright_axis(rig, side, plane, own, off, 20.0));
  }
  LocationParams params;
  params.frames = 1;
  params.lines_per_image = 1;
  LocationFinder thesis(rig, plane, std::nullopt, params);
  thesis.add_frame({explored.left, other.left}, {explored.right, other.right});
  ASSERT_EQ(thesis.intersects(), 1);
  EXPECT_LT((thesis.intersect_points()[0] - explored.base).norm(), 0.01) << "the strongest lines are the explored object's";
  params.explored = {explored.base};
  LocationFinder beyond(rig, plane, std::nullopt, params);
  beyond.add_frame({explored.left, other.left}, {explored.right, other.right});
  ASSERT_EQ(beyond.intersects(), 1);
  EXPECT_LT((beyond.intersect_points()[0] - other.base).norm(), 0.01);
  params.explored = {Eigen::Vector3d(NAN, 0, 0.6)};
  EXPECT_THROW(LocationFinder(rig, plane, std::nullopt, params), std::invalid_argument);
}

// The arm's base column is the strongest line of an image. Counted, it takes the one line a survey
// pairs per image (and its own pairing lies at the base, outside the workspace ring: nothing);
// uncounted, the next line is paired too; dropped, the next line is the only one.
TEST(GeometryLocations, TheArmBaseColumnsLineNeedNotTakeASurveysPlace) {
  const StereoRig rig = verged_rig(Lens::Typical);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis column = observe_axis(rig, table, 0.0, 0.85, 0.2), object = observe_axis(rig, table, -0.08, 0.6, 0.15);
  LocationParams params;
  params.frames = 1;
  params.lines_per_image = 1;
  const auto intersects_with = [&](LocationParams::ColumnLines mode) {
    params.column_lines = mode;
    LocationFinder finder(rig, plane, column.base, params);
    finder.add_frame({column.left, object.left}, {column.right, object.right});
    return finder.intersect_points();
  };
  EXPECT_TRUE(intersects_with(LocationParams::ColumnLines::Counted).empty());
  for (const auto mode : {LocationParams::ColumnLines::Uncounted, LocationParams::ColumnLines::Dropped}) {
    const std::vector<Eigen::Vector3d> points = intersects_with(mode);
    EXPECT_TRUE(std::any_of(points.begin(), points.end(), [&](const Eigen::Vector3d& p) { return (p - object.base).norm() < 0.01; }))
        << "mode " << static_cast<int>(mode);
  }
  EXPECT_EQ(intersects_with(LocationParams::ColumnLines::Dropped).size(), 1u);
  // Without an arm base there is no column to tell apart: every mode counts every line.
  params.column_lines = LocationParams::ColumnLines::Uncounted;
  LocationFinder no_base(rig, plane, std::nullopt, params);
  no_base.add_frame({column.left, object.left}, {column.right, object.right});
  ASSERT_EQ(no_base.intersects(), 1);
  EXPECT_LT((no_base.intersect_points()[0] - column.base).norm(), 0.01);
  EXPECT_EQ(parse_column_lines("uncounted"), LocationParams::ColumnLines::Uncounted);
  EXPECT_THROW(parse_column_lines("sometimes"), std::invalid_argument);
  params.column_line_px = 0;
  EXPECT_THROW(LocationFinder(rig, plane, column.base, params), std::invalid_argument);
}

// A stronger line that cannot be the image of an upright axis (turned 15 deg about its middle) is
// not among the lines a survey takes when it asks for upright lines only.
TEST(GeometryLocations, ASurveyCanTakeOnlyLinesThatCanBeUprightAxes) {
  const StereoRig rig = verged_rig(Lens::None);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis object = observe_axis(rig, table, 0.02, 0.6, 0.15);
  sym::Line leaning = object.left;
  leaning.theta += 15 * M_PI / 180;
  const cv::Point2d middle = 0.5 * (object.left.seg1 + object.left.seg2) - cv::Point2d(319.5, 239.5);
  leaning.r = middle.x * std::cos(leaning.theta) + middle.y * std::sin(leaning.theta);
  const double turn = 15 * M_PI / 180;  // the support segment turns with it
  for (cv::Point2d* end : {&leaning.seg1, &leaning.seg2}) {
    const cv::Point2d mid = 0.5 * (object.left.seg1 + object.left.seg2), d = *end - mid;
    *end = mid + cv::Point2d(d.x * std::cos(turn) - d.y * std::sin(turn), d.x * std::sin(turn) + d.y * std::cos(turn));
  }
  const auto tilt = upright_tilt_deg(rig, Side::Left, plane, leaning);
  ASSERT_TRUE(tilt.ok()) << tilt.reason();
  EXPECT_GT(*tilt, 3.0);
  LocationParams params;
  params.frames = 1;
  params.lines_per_image = 1;
  LocationFinder any(rig, plane, std::nullopt, params);
  any.add_frame({leaning, object.left}, {object.right});
  for (const Eigen::Vector3d& p : any.intersect_points())
    EXPECT_GT((p - object.base).norm(), 0.01) << "the strongest line is the leaning one: the object is not found";
  params.max_line_tilt_deg = 2;
  LocationFinder upright(rig, plane, std::nullopt, params);
  ASSERT_EQ(upright.add_frame({leaning, object.left}, {object.right}), 1);
  EXPECT_LT((upright.intersect_points()[0] - object.base).norm(), 0.01);
  params.max_line_tilt_deg = -1;
  EXPECT_THROW(LocationFinder(rig, plane, std::nullopt, params), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Lines that can be upright axes (issue 14)

// A 12 cm upright axis 0.55 m out on the table, seen by the verged rig through its lenses.
struct UprightScene {
  StereoRig rig = verged_rig(Lens::Typical);
  Table table;
  Plane plane = table_plane_in_right(rig, table);
  StereoAxis axis = observe_axis(rig, table, 0.03, 0.55, 0.12);
};

TEST(GeometryUpright, AnUprightAxisPassesATiltedOneAndATableLineDoNot) {
  const UprightScene scene;
  const StereoRig& rig = scene.rig;
  const Table& table = scene.table;
  const Plane& plane = scene.plane;
  const StereoAxis& upright = scene.axis;
  for (const Side side : {Side::Left, Side::Right}) {
    const auto tilt = upright_tilt_deg(rig, side, plane, side == Side::Left ? upright.left : upright.right);
    ASSERT_TRUE(tilt.ok()) << tilt.reason();
    EXPECT_LT(*tilt, 0.3);
  }
  // The same axis leaning 8 deg sideways (about the viewing direction), and a line on the table.
  auto left_line_of = [&](const Eigen::Vector3d& base, const Eigen::Vector3d& top) {
    std::vector<Eigen::Vector3d> along;
    for (int i = 0; i <= 60; ++i) along.push_back(base + (top - base) * (i / 60.0));
    return fit_line(project(along, rig.left, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero()), 640, 480);
  };
  const Eigen::Vector3d base = table.at(0.03, 0.55);
  const Eigen::Vector3d leaning = base + 0.12 * (std::cos(8 * kDeg) * table.up() + std::sin(8 * kDeg) * Eigen::Vector3d::UnitX());
  const sym::Line tilted = left_line_of(base, leaning);
  const sym::Line on_table = left_line_of(table.at(0.0, 0.5), table.at(0.02, 0.62));
  EXPECT_GT(*upright_tilt_deg(rig, Side::Left, plane, tilted), 5.0);
  EXPECT_GT(*upright_tilt_deg(rig, Side::Left, plane, on_table), 5.0);
  const std::vector<sym::Line> kept = upright_lines(rig, Side::Left, plane, {tilted, upright.left, on_table}, 2.0);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].r, upright.left.r);
  EXPECT_EQ(upright_lines(rig, Side::Left, plane, {tilted, upright.left, on_table}, 90.0).size(), 3u);
  EXPECT_THROW(upright_lines(rig, Side::Left, plane, {upright.left}, -1), std::invalid_argument);
}

// A line's support stands on the table at the object's foot (a little beyond it when its lowest
// edges are above the table); lines standing far from the arm are dropped, the others kept in order.
TEST(GeometryUpright, TheSupportStandsOnTheTableAtTheObjectsFoot) {
  const UprightScene scene;
  const StereoAxis& near = scene.axis;
  for (const Side side : {Side::Left, Side::Right}) {
    const auto foot = support_foot(scene.rig, side, scene.plane, side == Side::Left ? near.left : near.right);
    ASSERT_TRUE(foot.ok()) << foot.reason();
    EXPECT_LT((*foot - near.base).norm(), 0.003);
  }
  // Its lowest edges 3 cm above the table: the support stands beyond the foot, away from the camera.
  std::vector<Eigen::Vector3d> raised;
  const Eigen::Vector3d base = scene.table.at(0.03, 0.55);
  for (int i = 0; i <= 60; ++i) raised.push_back(base + (0.03 + 0.09 * i / 60.0) * scene.table.up());
  const sym::Line raised_right = fit_line(project(raised, scene.rig.right, scene.rig.R, scene.rig.T), 640, 480);
  const auto beyond = support_foot(scene.rig, Side::Right, scene.plane, raised_right);
  ASSERT_TRUE(beyond.ok()) << beyond.reason();
  EXPECT_GT(beyond->norm(), near.base.norm() + 0.02);
  EXPECT_LT(beyond->norm(), near.base.norm() + 0.10);

  const StereoAxis far = observe_axis(scene.rig, scene.table, -0.05, 0.85, 0.12);
  const std::vector<sym::Line> kept = lines_standing_within(scene.rig, Side::Right, scene.plane, near.base, 0.1, {far.right, near.right});
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].r, near.right.r);
  const std::vector<sym::Line> both = lines_standing_within(scene.rig, Side::Right, scene.plane, near.base, 0.5, {far.right, near.right});
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].r, far.right.r) << "in their order";
  // Around the far axis' foot with an inner radius: the far line stands inside it (the arm's base
  // column at the centre), the near one in the ring.
  const double apart = (far.base - near.base).norm();
  const std::vector<sym::Line> ring =
      lines_standing_within(scene.rig, Side::Right, scene.plane, far.base, apart + 0.05, {far.right, near.right}, 0.05);
  ASSERT_EQ(ring.size(), 1u);
  EXPECT_EQ(ring[0].r, near.right.r);
  EXPECT_THROW(lines_standing_within(scene.rig, Side::Right, scene.plane, near.base, 0.1, {near.right}, 0.1), std::invalid_argument);
  // A table behind the cameras is met by no ray: no foot, and the line is dropped.
  Plane behind;
  behind.normal = Eigen::Vector3d::UnitZ();
  behind.offset = 1.0;
  EXPECT_FALSE(support_foot(scene.rig, Side::Right, behind, near.right).ok());
  EXPECT_TRUE(lines_standing_within(scene.rig, Side::Right, behind, near.base, 0.5, {near.right}).empty());
  EXPECT_THROW(lines_standing_within(scene.rig, Side::Right, scene.plane, near.base, 0, {near.right}), std::invalid_argument);
}

TEST(GeometryUpright, SnapsALineOntoTheImageOfAnUprightAxis) {
  const StereoRig rig = verged_rig(Lens::Typical);
  const Table table;
  const Plane plane = table_plane_in_right(rig, table);
  const StereoAxis axis = observe_axis(rig, table, -0.04, 0.6, 0.1);
  // The right view's line turned 1.5 deg about its middle, as a coarse accumulator bin leaves it.
  sym::Line turned = axis.right;
  const cv::Point2d middle = 0.5 * (turned.seg1 + turned.seg2);
  turned.theta += 1.5 * kDeg;
  turned.r = (middle.x - 319.5) * std::cos(turned.theta) + (middle.y - 239.5) * std::sin(turned.theta);
  EXPECT_GT(*upright_tilt_deg(rig, Side::Right, plane, turned), 0.5);
  const auto snapped = snapped_upright(rig, Side::Right, plane, turned);
  ASSERT_TRUE(snapped.ok()) << snapped.reason();
  EXPECT_LT(*upright_tilt_deg(rig, Side::Right, plane, *snapped), 0.05);
  EXPECT_NEAR(snapped->theta, axis.right.theta, 0.1 * kDeg);
  EXPECT_NEAR(snapped->r, axis.right.r, 0.5);
  // upright_lines with snap returns the snapped line.
  const auto kept = upright_lines(rig, Side::Right, plane, {turned}, 5.0, true);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_NEAR(kept[0].theta, snapped->theta, 1e-12);
}

// The arm's base column in the shipped simulation calibration: both cameras see it; the mask
// covers its axis from the table up, is about as wide as the column seen from there, and leaves
// the table beside it alone.
TEST(GeometryColumnMask, CoversTheArmsBaseColumnInBothCameras) {
  const std::string shipped = std::string(NUDGE_SOURCE_DIR) + "/config/calibration_sim.yaml";
  const StereoRig rig = load_rig(shipped);
  const Workspace scene = load_workspace(shipped);
  ASSERT_TRUE(scene.table && scene.arm_base);
  Column column;
  column.foot = *scene.arm_base;
  column.radius = 0.07;
  column.height = 0.4;
  const Eigen::Vector3d n = scene.table->normal.normalized();
  const Eigen::Vector3d up = scene.table->signed_distance(Eigen::Vector3d::Zero()) >= 0 ? n : Eigen::Vector3d(-n);
  const Eigen::Vector3d foot = column.foot - scene.table->signed_distance(column.foot) * n;
  for (const Side side : {Side::Left, Side::Right}) {
    const Camera& camera = side == Side::Left ? rig.left : rig.right;
    const auto project = [&](const Eigen::Vector3d& p) {
      const Eigen::Vector3d q = side == Side::Left ? Eigen::Vector3d(rig.R.transpose() * (p - rig.T)) : p;
      const Eigen::Vector2d px = camera.project(q);
      return cv::Point(cvRound(px.x()), cvRound(px.y()));
    };
    const cv::Mat mask = column_mask(rig, side, *scene.table, column, 0);
    ASSERT_EQ(mask.size(), cv::Size(camera.width, camera.height));
    for (double h : {0.01, 0.1, 0.2, 0.25}) {  // its top is above the pictures
      const cv::Point p = project(foot + h * up);
      ASSERT_TRUE(cv::Rect(0, 0, mask.cols, mask.rows).contains(p)) << "the column is in view";
      EXPECT_EQ(mask.at<uint8_t>(p), 255) << "its axis at " << h << " m";
    }
    // Its width across the middle: 2 r f / depth, within a tenth.
    const Eigen::Vector3d middle = foot + 0.2 * up;
    const Eigen::Vector3d in_camera = side == Side::Left ? Eigen::Vector3d(rig.R.transpose() * (middle - rig.T)) : middle;
    const cv::Point c = project(middle);
    const int width = cv::countNonZero(mask.row(c.y));
    EXPECT_NEAR(width, 2 * column.radius * camera.K(0, 0) / in_camera.norm(), 0.1 * width);
    // The table 20 cm to the side is not masked.
    const Eigen::Vector3d side_dir = up.cross(in_camera).normalized();
    EXPECT_EQ(mask.at<uint8_t>(project(foot + 0.2 * side_dir + 0.05 * up)), 0);
    // The margin widens it.
    EXPECT_GT(cv::countNonZero(column_mask(rig, side, *scene.table, column, 4)), cv::countNonZero(mask));
  }
  // Behind the cameras: nothing to mask. Bad sizes are named.
  Column behind = column;
  behind.foot = Eigen::Vector3d(0, 0, -2);
  EXPECT_EQ(cv::countNonZero(column_mask(rig, Side::Right, *scene.table, behind)), 0);
  Column flat = column;
  flat.height = 0;
  EXPECT_THROW(column_mask(rig, Side::Right, *scene.table, flat), std::invalid_argument);
  EXPECT_THROW(column_mask(rig, Side::Right, *scene.table, column, -1), std::invalid_argument);
}

// Several columns (the objects a survey has explored): the union of each one's region, or of each
// one's outline band, so that where two overlap neither loses its silhouette.
TEST(GeometryColumnMask, SeveralColumnsMaskEachOnesRegionOrOutline) {
  const std::string shipped = std::string(NUDGE_SOURCE_DIR) + "/config/calibration_sim.yaml";
  const StereoRig rig = load_rig(shipped);
  const Workspace scene = load_workspace(shipped);
  ASSERT_TRUE(scene.table && scene.arm_base);
  const Eigen::Vector3d toward_camera = -scene.arm_base->normalized();  // the base from the right camera, reversed
  Column a, b;
  a.foot = *scene.arm_base + 0.25 * toward_camera;
  b.foot = a.foot + 0.06 * scene.table->normal.normalized().cross(toward_camera).normalized();  // beside a, overlapping
  a.radius = b.radius = 0.04;
  a.height = b.height = 0.12;
  for (const Side side : {Side::Left, Side::Right}) {
    const cv::Mat region_a = column_mask(rig, side, *scene.table, a, 4), region_b = column_mask(rig, side, *scene.table, b, 4);
    ASSERT_GT(cv::countNonZero(region_a & region_b), 0) << "the two overlap in the image";
    EXPECT_EQ(cv::countNonZero(columns_mask(rig, side, *scene.table, {a, b}, 4, 0) != (region_a | region_b)), 0);
    const cv::Mat bands = outline_band(column_mask(rig, side, *scene.table, a, 0), 3) |
                          outline_band(column_mask(rig, side, *scene.table, b, 0), 3);
    const cv::Mat banded = columns_mask(rig, side, *scene.table, {a, b}, 4, 3);
    EXPECT_EQ(cv::countNonZero(banded != bands), 0);
    EXPECT_GT(cv::countNonZero(banded & region_a & region_b), 0) << "the outlines inside the overlap are kept out too";
    EXPECT_EQ(cv::countNonZero(columns_mask(rig, side, *scene.table, {}, 4, 0)), 0) << "nothing explored";
  }
  EXPECT_THROW(columns_mask(rig, Side::Right, *scene.table, {a}, 4, -1), std::invalid_argument);
}

// The band either side of a region's outline: the silhouette's edges, not what lies inside.
TEST(GeometryColumnMask, OutlineBandKeepsTheSilhouetteNotTheInside) {
  cv::Mat region(100, 100, CV_8UC1, cv::Scalar(0));
  region(cv::Rect(30, 10, 40, 80)).setTo(255);
  const cv::Mat band = outline_band(region, 3);
  EXPECT_EQ(band.at<uint8_t>(50, 30), 255) << "on the left side";
  EXPECT_EQ(band.at<uint8_t>(50, 69), 255) << "on the right side";
  EXPECT_EQ(band.at<uint8_t>(50, 27), 255) << "3 px outside";
  EXPECT_EQ(band.at<uint8_t>(50, 50), 0) << "the inside is kept";
  EXPECT_EQ(band.at<uint8_t>(50, 20), 0) << "beyond the band";
  EXPECT_THROW(outline_band(region, 0), std::invalid_argument);
  EXPECT_THROW(outline_band(cv::Mat(10, 10, CV_8UC3), 2), std::invalid_argument);
}

// ---- The table's own texture, by stereo (table_texture.hpp) ----

namespace {

// The rig's cameras at 320x240 (the ray casting below is 4 rays a pixel).
StereoRig half_size(StereoRig rig) {
  for (Camera* camera : {&rig.left, &rig.right}) {
    camera->width /= 2;
    camera->height /= 2;
    camera->K.topRows(2) *= 0.5;
    camera->K(0, 2) -= 0.25;  // pixel centres: x_half = (x + 0.5) / 2 - 0.5
    camera->K(1, 2) -= 0.25;
  }
  return rig;
}

// Both cameras' pictures of a checkered table (6 cm squares) with an upright white card standing
// on it (7 cm wide, 15 cm tall, facing the cameras), ray-cast through the rig's lens model with
// 2x2 rays a pixel (a renderer's anti-aliasing: hard-edged squares sampled once a pixel differ
// between the views by a pixel's worth of aliasing along every edge). The
// truth per pixel: 0 the table, 1 the card, 2 the table where the card hides it from the other camera.
struct CardScene {
  StereoRig rig = half_size(verged_rig(Lens::Typical));
  Plane table;  // right camera frame
  Eigen::Vector3d up, foot, across;
  double half_width = 0.035, height = 0.15;

  CardScene() {
    const Table t;
    up = rig.R * t.up();
    const Eigen::Vector3d on_table = rig.left_to_right(t.at(0, 0.75));
    table.normal = up;
    table.offset = -up.dot(on_table);
    foot = rig.left_to_right(t.at(0.03, 0.75));
    const Eigen::Vector3d middle_of_cameras = rig.left_centre() / 2;
    across = up.cross(foot - middle_of_cameras).normalized();
  }

  // Ray from `origin` along `dir` (right camera frame): the label and the grey level it sees.
  // The card's hit distance along a ray, or infinity.
  double card_hit(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const {
    const Eigen::Vector3d facing = across.cross(up);
    const double along_card = facing.dot(dir);
    if (std::abs(along_card) < 1e-12) return INFINITY;
    const double t = facing.dot(foot - origin) / along_card;
    const Eigen::Vector3d q = origin + t * dir - foot;
    return t > 0 && std::abs(q.dot(across)) <= half_width && q.dot(up) >= 0 && q.dot(up) <= height ? t : INFINITY;
  }

  // Ray from `origin` along `dir` (right camera frame), the other camera at `other_origin`: the
  // label (0 the table, 2 the table hidden from the other camera by the card, 1 the card) and the
  // grey level it sees.
  std::pair<int, int> trace(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, const Eigen::Vector3d& other_origin) const {
    double best = 1e9;
    std::pair<int, int> seen{0, 0};
    const double along_table = table.normal.dot(dir);
    if (std::abs(along_table) > 1e-12) {
      const double t = -(table.normal.dot(origin) + table.offset) / along_table;
      if (t > 0) {
        best = t;
        const Eigen::Vector3d q = origin + t * dir - foot;
        const int square = static_cast<int>(std::floor(q.dot(across) / 0.06)) + static_cast<int>(std::floor(q.dot(up.cross(across)) / 0.06));
        const Eigen::Vector3d to_other = other_origin - (origin + t * dir);
        const bool hidden = card_hit(origin + t * dir, to_other.normalized()) < to_other.norm();
        seen = {hidden ? 2 : 0, (square & 1) ? 170 : 80};
      }
    }
    if (card_hit(origin, dir) < best) seen = {1, 235};
    return seen;
  }

  // The picture (BGR, `brightness` added) and the truth labels of one camera.
  std::pair<cv::Mat, cv::Mat> render(Side side, int brightness = 0) const {
    const Camera& camera = side == Side::Left ? rig.left : rig.right;
    cv::Mat image(camera.height, camera.width, CV_8UC3), labels(camera.height, camera.width, CV_8UC1);
    const Eigen::Vector3d origin = side == Side::Left ? rig.left_centre() : Eigen::Vector3d::Zero();
    const Eigen::Vector3d other_origin = side == Side::Left ? Eigen::Vector3d::Zero() : rig.left_centre();
    for (int v = 0; v < camera.height; ++v)
      for (int u = 0; u < camera.width; ++u) {
        int sum = 0, card_rays = 0, hidden_rays = 0;
        for (const double dv : {-0.25, 0.25})
          for (const double du : {-0.25, 0.25}) {
            const auto n = camera.normalise(Eigen::Vector2d(u + du, v + dv));
            Eigen::Vector3d dir(n.value().x(), n.value().y(), 1.0);
            if (side == Side::Left) dir = rig.R * dir;
            const auto [label, grey] = trace(origin, dir, other_origin);
            sum += grey;
            card_rays += label == 1;
            hidden_rays += label == 2;
          }
        labels.at<uint8_t>(v, u) = card_rays >= 2 ? 1 : hidden_rays > 0 ? 2 : 0;
        image.at<cv::Vec3b>(v, u) = cv::Vec3b::all(cv::saturate_cast<uint8_t>(sum / 4 + brightness));
      }
    return {image, labels};
  }
};

}  // namespace

// The warp takes a point of the table seen in one camera to where the other camera sees it,
// through both lenses; above the horizon it is undefined.
TEST(GeometryTableTexture, ThePlaneWarpMapsTablePointsBetweenTheCameras) {
  const CardScene scene;
  for (const Side to : {Side::Left, Side::Right}) {
    const PlaneWarp warp = plane_warp(scene.rig, to, scene.table);
    const Camera& camera = to == Side::Left ? scene.rig.left : scene.rig.right;
    const Camera& other = to == Side::Left ? scene.rig.right : scene.rig.left;
    ASSERT_EQ(warp.size(), cv::Size(camera.width, camera.height));
    EXPECT_EQ(warp.other_size, cv::Size(other.width, other.height));
    const Table t;
    for (const auto& [lateral, distance] : std::vector<std::pair<double, double>>{{0, 0.7}, {-0.15, 0.6}, {0.1, 0.9}}) {
      const Eigen::Vector3d p = scene.rig.left_to_right(t.at(lateral, distance));
      const Eigen::Vector3d in_left = scene.rig.R.transpose() * (p - scene.rig.T);
      const Eigen::Vector2d here = to == Side::Left ? scene.rig.left.project(in_left) : scene.rig.right.project(p);
      const Eigen::Vector2d there = to == Side::Left ? scene.rig.right.project(p) : scene.rig.left.project(in_left);
      const cv::Point px(cvRound(here.x()), cvRound(here.y()));
      ASSERT_TRUE(cv::Rect(0, 0, camera.width, camera.height).contains(px));
      // The warp is exact at pixel centres; `px` is up to half a pixel off `here`, which the
      // plane's homography magnifies by about the ratio of the two depths.
      EXPECT_NEAR(warp.map_x.at<float>(px), there.x(), 1.0) << lateral << ", " << distance;
      EXPECT_NEAR(warp.map_y.at<float>(px), there.y(), 1.0) << lateral << ", " << distance;
    }
  }
  // A plane behind both cameras is seen nowhere: the warp is undefined everywhere.
  Plane behind;
  behind.normal = Eigen::Vector3d::UnitZ();
  behind.offset = 1.0;  // z = -1 m
  EXPECT_EQ(cv::countNonZero(plane_warp(scene.rig, Side::Right, behind).map_x >= 0), 0);
  Plane flat = scene.table;
  flat.normal.setZero();
  EXPECT_THROW(plane_warp(scene.rig, Side::Right, flat), std::invalid_argument);
}

// The checkered table agrees between the two views and is marked; the standing card's outline
// does not (only its foot, on the table) and keeps its edges.
TEST(GeometryTableTexture, MarksTheCheckeredTableNotTheStandingCard) {
  const CardScene scene;
  const auto [left, left_labels] = scene.render(Side::Left, 4);  // a camera a little brighter
  const auto [right, right_labels] = scene.render(Side::Right);
  for (const Side side : {Side::Left, Side::Right}) {
    const cv::Mat& image = side == Side::Left ? left : right;
    const cv::Mat& other = side == Side::Left ? right : left;
    const cv::Mat& labels = side == Side::Left ? left_labels : right_labels;
    const PlaneWarp warp = plane_warp(scene.rig, side, scene.table);
    const cv::Mat table = table_texture_mask(image, other, warp);
    ASSERT_EQ(table.size(), image.size());
    ASSERT_EQ(table.type(), CV_8UC1);

    // The card's outline: card pixels next to the table, 3 cm or more above its foot.
    cv::Mat card = labels == 1, table_truth = labels == 0;
    cv::Mat near_table;
    cv::dilate(labels != 1, near_table, cv::Mat());
    cv::Mat outline = card & near_table;
    // Its foot: the lowest 3 cm of the card's image, measured as rows above its bottom.
    cv::Rect box = cv::boundingRect(card);
    const double foot_rows = box.height * 0.03 / scene.height;
    outline(cv::Rect(0, box.y + box.height - static_cast<int>(std::ceil(foot_rows)) - 1, outline.cols,
                     static_cast<int>(std::ceil(foot_rows)) + 1)).setTo(0);
    ASSERT_GT(cv::countNonZero(outline), 100);
    EXPECT_LT(cv::countNonZero(outline & table), 0.05 * cv::countNonZero(outline)) << "the card's outline is kept";

    // The table that both cameras see, away from the card (10 px) and inside the other camera's
    // view (the warp defined 8 px around): almost all of it is marked.
    cv::Mat away;
    cv::dilate(card, away, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(21, 21)));
    cv::Mat seen_by_both = warp.map_x >= 0;
    cv::erode(seen_by_both, seen_by_both, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(17, 17)), cv::Point(-1, -1), 1,
              cv::BORDER_CONSTANT, cv::Scalar(0));  // and 8 px inside the image's border
    const cv::Mat open_table = table_truth & ~away & seen_by_both;
    ASSERT_GT(cv::countNonZero(open_table), 20000);
    EXPECT_GT(cv::countNonZero(open_table & table), 0.97 * cv::countNonZero(open_table)) << "the table is marked";
  }
}

TEST(GeometryTableTexture, BadImagesAndParametersAreNamed) {
  const CardScene scene;
  const PlaneWarp warp = plane_warp(scene.rig, Side::Right, scene.table);
  const cv::Mat image(warp.size(), CV_8UC3, cv::Scalar::all(100));
  EXPECT_THROW(table_texture_mask(cv::Mat(), image, warp), std::invalid_argument);
  EXPECT_THROW(table_texture_mask(image, cv::Mat(), warp), std::invalid_argument);
  EXPECT_THROW(table_texture_mask(image, cv::Mat(10, 10, CV_8UC3), warp), std::invalid_argument);
  EXPECT_THROW(table_texture_mask(cv::Mat(warp.size(), CV_16UC1), image, warp), std::invalid_argument);
  EXPECT_THROW(table_texture_mask(cv::Mat(warp.size(), CV_8UC4), image, warp), std::invalid_argument);
  using Change = void (*)(TableTextureParams&);
  for (const Change bad : {Change([](TableTextureParams& p) { p.window_radius = 0; }),
                           Change([](TableTextureParams& p) { p.search_px = -1; }),
                           Change([](TableTextureParams& p) { p.max_difference = 0; }),
                           Change([](TableTextureParams& p) { p.margin_px = -1; }),
                           Change([](TableTextureParams& p) { p.blur_sigma = -1; })}) {
    TableTextureParams params;
    bad(params);
    EXPECT_THROW(validate(params), std::invalid_argument);
    EXPECT_THROW(table_texture_mask(image, image, warp, params), std::invalid_argument);
  }
  // Grey images work as BGR ones do.
  cv::Mat grey(warp.size(), CV_8UC1, cv::Scalar(100));
  EXPECT_EQ(table_texture_mask(grey, grey, warp).size(), warp.size());
}

namespace {

// The card's axis (right camera frame), its image line in one camera of the scene, and the scene's
// pictures with the right camera's card painted another colour: what a pairing of one object's
// left line with another object's right line looks like along the axis.
Segment3 card_axis(const CardScene& scene) { return {scene.foot, scene.foot + scene.height * scene.up}; }

sym::Line card_line(const CardScene& scene, Side side) {
  std::vector<cv::Point2d> pixels;
  for (int i = 0; i <= 30; ++i) {
    const Eigen::Vector3d p = scene.foot + (scene.height * i / 30.0) * scene.up;
    const Eigen::Vector2d q = side == Side::Left ? scene.rig.left.project(scene.rig.R.transpose() * (p - scene.rig.T))
                                                 : scene.rig.right.project(p);
    pixels.emplace_back(q.x(), q.y());
  }
  const Camera& camera = side == Side::Left ? scene.rig.left : scene.rig.right;
  return fit_line(pixels, camera.width, camera.height);
}

cv::Mat repainted_card(const std::pair<cv::Mat, cv::Mat>& picture) {
  cv::Mat image = picture.first.clone();
  image.setTo(cv::Scalar(40, 40, 200), picture.second == 1);
  return image;
}

}  // namespace

// Both cameras see the card along its own axis; with the right camera's card another colour (the
// right line another object's) they see different things at every height.
TEST(GeometryAxisAppearance, BothCamerasSeeTheObjectAlongItsAxisAndNotAlongAPhantoms) {
  const CardScene scene;
  const auto left = scene.render(Side::Left, 4), right = scene.render(Side::Right);
  const Segment3 axis = card_axis(scene);
  const auto same = axis_colour_agreement(scene.rig, left.first, right.first, axis, scene.foot, scene.table, 0.14);
  ASSERT_TRUE(same.ok()) << same.reason();
  EXPECT_GE(*same, 0.95);
  const auto phantom =
      axis_colour_agreement(scene.rig, left.first, repainted_card(right), axis, scene.foot, scene.table, 0.14);
  ASSERT_TRUE(phantom.ok()) << phantom.reason();
  EXPECT_LE(*phantom, 0.05);
  // Grey images are compared as grey.
  cv::Mat left_grey, right_grey;
  cv::cvtColor(left.first, left_grey, cv::COLOR_BGR2GRAY);
  cv::cvtColor(right.first, right_grey, cv::COLOR_BGR2GRAY);
  EXPECT_GE(axis_colour_agreement(scene.rig, left_grey, right_grey, axis, scene.foot, scene.table, 0.14).value(), 0.95);
}

TEST(GeometryAxisAppearance, BadImagesHeightsAndParametersAreNamed) {
  const CardScene scene;
  const auto left = scene.render(Side::Left), right = scene.render(Side::Right);
  const Segment3 axis = card_axis(scene);
  try {
    axis_colour_agreement(scene.rig, cv::Mat(480, 640, CV_8UC3), right.first, axis, scene.foot, scene.table, 0.1);
    FAIL() << "a left image of the wrong size was taken";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("left image"), std::string::npos) << e.what();
  }
  EXPECT_THROW(axis_colour_agreement(scene.rig, left.first, cv::Mat(), axis, scene.foot, scene.table, 0.1),
               std::invalid_argument);
  // Below the first height looked at there is nothing to compare: no verdict, not a pass.
  const auto too_low = axis_colour_agreement(scene.rig, left.first, right.first, axis, scene.foot, scene.table, 0.005);
  ASSERT_FALSE(too_low.ok());
  EXPECT_NE(too_low.reason().find("heights"), std::string::npos) << too_low.reason();
  AxisAppearanceParams bad;
  bad.step_m = 0;
  EXPECT_THROW(axis_colour_agreement(scene.rig, left.first, right.first, axis, scene.foot, scene.table, 0.1, bad),
               std::invalid_argument);
}

// With min_axis_colour_agreement the finder takes the frame's images and keeps the card's pairing
// only where both cameras see the card; without images it refuses to guess.
TEST(GeometryAxisAppearance, LocationFinderDropsPairingsTheImagesDisagreeOn) {
  const CardScene scene;
  const auto left = scene.render(Side::Left), right = scene.render(Side::Right);
  const std::vector<sym::Line> left_lines = {card_line(scene, Side::Left)}, right_lines = {card_line(scene, Side::Right)};
  LocationParams params;
  params.frames = 1;
  params.min_axis_colour_agreement = 0.5;
  params.appearance_waived_at_overlap = 2;  // never: the two support segments cover the same heights
  LocationFinder finder(scene.rig, scene.table, std::nullopt, params);
  EXPECT_THROW(finder.add_frame(left_lines, right_lines), std::invalid_argument);
  EXPECT_EQ(finder.frame_axes(left_lines, right_lines, left.first, right.first).size(), 1u);
  EXPECT_TRUE(finder.frame_axes(left_lines, right_lines, left.first, repainted_card(right)).empty());
  EXPECT_EQ(finder.add_frame(left_lines, right_lines, left.first, right.first), 1);
  ASSERT_EQ(finder.intersect_points().size(), 1u);
  EXPECT_LT((finder.intersect_points()[0] - scene.foot).norm(), 0.01);
  // Support segments that agree as well as these (the whole card in both images) say "one object"
  // by themselves: the appearance is not asked.
  params.appearance_waived_at_overlap = 0.7;
  const LocationFinder waived(scene.rig, scene.table, std::nullopt, params);
  EXPECT_EQ(waived.frame_axes(left_lines, right_lines, left.first, repainted_card(right)).size(), 1u);
  params.appearance_waived_at_overlap = -1;
  EXPECT_THROW(LocationFinder(scene.rig, scene.table, std::nullopt, params), std::invalid_argument);
  params.appearance_waived_at_overlap = 0.7;
  params.min_axis_colour_agreement = 1.5;
  EXPECT_THROW(LocationFinder(scene.rig, scene.table, std::nullopt, params), std::invalid_argument);
}
