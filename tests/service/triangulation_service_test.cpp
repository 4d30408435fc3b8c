// Service test: nudge-triangulation as a pure function from log to log. The input log holds
// SYMMETRY_LEFT / SYMMETRY_RIGHT messages made by projecting known vertical axes through a known
// verged rig with lens distortion (cv::projectPoints), a candidates request, and bad input: a line
// with NaNs, an image size that disagrees with the calibration, a message without a partner.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <Eigen/Geometry>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>  // after Eigen, as OpenCV requires
#include <opencv2/imgproc.hpp>

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <set>
#include <string>

#include "nudge/axes_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/workspace.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/run_service.hpp"

namespace geo = nudge::geometry;
namespace sym = nudge::symmetry;
namespace channel = nudge::bus::channel;

namespace {

using nudge::test::encode;
using nudge::test::LogWriter;

constexpr double kDeg = M_PI / 180.0;
constexpr int kWidth = 640, kHeight = 480;

// The verged rig of geometry_test: 0.25 m baseline, 15 deg vergence, 1 deg roll, webcam distortion.
geo::StereoRig verged_rig() {
  geo::StereoRig rig;
  rig.left.K << 620, 0, 322.5, 0, 620 * 1.002, 236.0, 0, 0, 1;
  rig.left.distortion = {-0.15, 0.07, 0.0012, -0.0008, -0.01};
  rig.right.K << 610, 0, 317.0, 0, 610 * 1.002, 243.5, 0, 0, 1;
  rig.right.distortion = {-0.13, 0.05, -0.0006, 0.0010, 0.0};
  const Eigen::Matrix3d right_axes_in_left =
      (Eigen::AngleAxisd(-15 * kDeg, Eigen::Vector3d::UnitY()) * Eigen::AngleAxisd(1 * kDeg, Eigen::Vector3d::UnitZ()))
          .toRotationMatrix();
  rig.R = right_axes_in_left.transpose();
  rig.T = -rig.R * Eigen::Vector3d(0.25, 0.005, 0.0);
  return rig;
}

// The table in the left camera's frame: cameras 0.45 m above it, pitched 30 deg down.
Eigen::Vector3d table_up() { return {0, -std::cos(30 * kDeg), -std::sin(30 * kDeg)}; }
Eigen::Vector3d table_at(double lateral, double distance) {
  const Eigen::Vector3d forward(0, -std::sin(30 * kDeg), std::cos(30 * kDeg));
  return lateral * Eigen::Vector3d::UnitX() + distance * forward - 0.45 * table_up();
}

std::vector<cv::Point2d> project(const std::vector<Eigen::Vector3d>& points, const geo::Camera& camera,
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

// Total-least-squares (R, theta) line through image points, support segment spanning them.
sym::Line fit_line(const std::vector<cv::Point2d>& points) {
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean *= 1.0 / points.size();
  double sxx = 0, syy = 0, sxy = 0;
  for (const auto& p : points) {
    sxx += (p.x - mean.x) * (p.x - mean.x);
    syy += (p.y - mean.y) * (p.y - mean.y);
    sxy += (p.x - mean.x) * (p.y - mean.y);
  }
  const double along = 0.5 * std::atan2(2 * sxy, sxx - syy);
  Eigen::Vector2d normal(-std::sin(along), std::cos(along));
  double theta = std::atan2(normal.y(), normal.x());
  if (theta <= -M_PI / 2) theta += M_PI, normal = -normal;
  if (theta > M_PI / 2) theta -= M_PI, normal = -normal;
  sym::Line line;
  line.theta = theta;
  line.r = normal.x() * (mean.x - 0.5 * (kWidth - 1)) + normal.y() * (mean.y - 0.5 * (kHeight - 1));
  line.votes = 100;
  line.seg1 = points.front();
  line.seg2 = points.back();
  sym::border_endpoints(line.r, line.theta, kWidth, kHeight, &line.end1, &line.end2);
  return line;
}

struct Object {
  std::string name;
  Eigen::Vector3d base_right;  // where the axis meets the table, right camera frame
  sym::Line left, right;
  bool in_ring;
};

Object observe(const geo::StereoRig& rig, const std::string& name, double lateral, double distance, bool in_ring) {
  const Eigen::Vector3d base = table_at(lateral, distance), top = base + 0.18 * table_up();
  std::vector<Eigen::Vector3d> along;
  for (int i = 0; i <= 40; ++i) along.push_back(base + (top - base) * (i / 40.0));
  const auto left = project(along, rig.left, Eigen::Matrix3d::Identity(), Eigen::Vector3d::Zero());
  const auto right = project(along, rig.right, rig.R, rig.T);
  for (const auto& p : left) EXPECT_TRUE(p.inside(cv::Rect2d(0, 0, kWidth - 1, kHeight - 1))) << name << " left";
  for (const auto& p : right) EXPECT_TRUE(p.inside(cv::Rect2d(0, 0, kWidth - 1, kHeight - 1))) << name << " right";
  return {name, rig.left_to_right(base), fit_line(left), fit_line(right), in_ring};
}

// n . p + d = 0 in the right camera's frame.
std::array<double, 4> table_plane_in_right(const geo::StereoRig& rig) {
  const Eigen::Vector3d n = rig.R * table_up(), p = rig.left_to_right(table_at(0, 0.6));
  return {n.x(), n.y(), n.z(), -n.dot(p)};
}

nudge::symmetry_lines_t lines_message(const std::vector<sym::Line>& lines, int64_t utime, const std::string& camera) {
  sym::Result result;
  result.width = kWidth;
  result.height = kHeight;
  result.num_edges = 5000;
  result.lines = lines;
  return nudge::bus::to_message(result, utime, utime / 1000, camera);
}

// A directory of this process's own: other builds' test runs may share the temporary directory.
std::string scratch_dir() {
  const std::string dir = testing::TempDir() + "/nudge_triangulation_test_" + std::to_string(::getpid());
  ::mkdir(dir.c_str(), 0755);
  return dir;
}

std::string bin(const std::string& name) { return std::string(NUDGE_BIN_DIR) + "/" + name; }

// Runs a command; its standard error into *err. Returns the exit code (-1 if killed).
int run(const std::string& cmd, std::string* err = nullptr) {
  const auto result = nudge::test::run_capturing(cmd);
  if (err) *err = result.err;
  return result.exit_code;
}

struct Scene {
  geo::StereoRig rig = verged_rig();
  // The arm stands on the table behind the objects; two objects inside its 150-350 mm ring, one
  // outside (in AXES, not a candidate).
  Eigen::Vector3d arm_base_right = rig.left_to_right(table_at(0.05, 0.85));
  std::vector<Object> objects;
  Scene() {
    objects.push_back(observe(rig, "inside A", -0.05, 0.60, true));
    objects.push_back(observe(rig, "inside B", 0.12, 0.66, true));
    objects.push_back(observe(rig, "outside C", -0.16, 0.48, false));
  }
};

constexpr int kFrames = 25;
constexpr int64_t kStart = 1000000, kPeriod = 100000;
// Right-image order of the objects differs from the left's, and changes each frame.
int right_order(int frame, int k) { return (k + frame) % 3; }

// The good frames; frame 7's left lines also carry a NaN line; frame 12's right image has the wrong
// size (skipped, so its left partner goes unmatched); a lone left message at the end.
// The request comes first in the log, stamped `request_utime` (a later one: the lines of the
// frames before it arrive late, as from a lagging pipeline).
// `explored`: places sent with the request (table frame).
void write_input_log(const Scene& scene, const std::string& path, int64_t request_utime = kStart - 1,
                     int request_frames = 20, const std::vector<Eigen::Vector3d>& explored = {},
                     double max_line_tilt_deg = 0) {
  LogWriter log(path);
  nudge::candidates_request_t request;
  request.utime = request_utime;
  request.frames = request_frames;
  request.lines_per_image = 3;
  request.max_line_tilt_deg = max_line_tilt_deg;
  for (const Eigen::Vector3d& place : explored) request.explored.push_back({place.x(), place.y(), place.z()});
  request.num_explored = static_cast<int32_t>(request.explored.size());
  log.raw(request.utime, "CANDIDATES_REQUEST", encode(request));
  for (int f = 0; f < kFrames; ++f) {
    const int64_t utime = kStart + f * kPeriod;
    std::vector<sym::Line> left, right(3);
    for (int k = 0; k < 3; ++k) {
      left.push_back(scene.objects[k].left);
      right[right_order(f, k)] = scene.objects[k].right;
    }
    if (f == 7) {
      sym::Line bad = left[0];
      bad.r = std::numeric_limits<double>::quiet_NaN();
      left.push_back(bad);
    }
    auto right_msg = lines_message(right, utime, "right");
    if (f == 12) right_msg.width = 320;
    const auto left_bytes = encode(lines_message(left, utime, "left")), right_bytes = encode(right_msg);
    if (f % 2) {  // either half may arrive first
      log.raw(utime, "SYMMETRY_LEFT", left_bytes);
      log.raw(utime + 10, "SYMMETRY_RIGHT", right_bytes);
    } else {
      log.raw(utime, "SYMMETRY_RIGHT", right_bytes);
      log.raw(utime + 10, "SYMMETRY_LEFT", left_bytes);
    }
  }
  log.raw(kStart + kFrames * kPeriod, "SYMMETRY_LEFT",
              encode(lines_message({scene.objects[0].left}, kStart + kFrames * kPeriod, "left")));
}

struct Output {
  std::map<int64_t, nudge::axes_t> axes;
  std::vector<nudge::candidates_t> candidates;
  int64_t errors = -1;
  std::string status;
};

Output read_output(const std::string& path) {
  const auto events = nudge::test::read_log(path);
  Output out;
  for (const auto& m : nudge::test::messages_on<nudge::axes_t>(events, "AXES")) out.axes[m.utime] = m;
  out.candidates = nudge::test::messages_on<nudge::candidates_t>(events, "CANDIDATES");
  const auto heartbeats = nudge::test::messages_on<nudge::heartbeat_t>(events, "HEARTBEAT");
  if (!heartbeats.empty()) {
    out.errors = heartbeats.back().errors;
    out.status = heartbeats.back().status;
  }
  return out;
}

// The flags that give the service the scene's table plane and arm base.
std::string table_flags(const Scene& scene) {
  const auto plane = table_plane_in_right(scene.rig);
  char flags[256];
  std::snprintf(flags, sizeof flags, " --table-plane %.12f %.12f %.12f %.12f --arm-base %.12f %.12f %.12f", plane[0],
                plane[1], plane[2], plane[3], scene.arm_base_right.x(), scene.arm_base_right.y(),
                scene.arm_base_right.z());
  return flags;
}

// One run of nudge-triangulation from a log to a log, its files (the rig, the input and the
// output log) named by `tag` in this process's scratch folder.
struct ServiceRun {
  explicit ServiceRun(const std::string& tag)
      : rig(scratch_dir() + "/triangulation_" + tag + "_rig.yaml"),
        in(scratch_dir() + "/triangulation_" + tag + "_in.lcmlog"),
        out(scratch_dir() + "/triangulation_" + tag + "_out.lcmlog") {}

  // The service's command line on these files, `flags` added.
  std::string command(const std::string& flags = "") const {
    return bin("nudge-triangulation") + " --calibration " + rig + flags + " --lcm-in 'file://" + in +
           "?speed=0' --lcm-out 'file://" + out + "?mode=w'";
  }
  // Runs command(flags) on a fresh output log; its standard error in `err`. The exit code.
  int operator()(const std::string& flags = "") {
    std::remove(out.c_str());
    return run(command(flags), &err);
  }

  std::string rig, in, out, err;
};

Eigen::Vector3d vec(const double v[3]) { return {v[0], v[1], v[2]}; }

// Everything the full input log must produce, however the table and arm base were given.
void expect_axes_and_candidates(const Scene& scene, const Output& result, const std::string& err) {
  // The test's own view of the table frame (z up, origin at the arm base's foot).
  const auto p = table_plane_in_right(scene.rig);
  geo::Plane table;
  table.normal = Eigen::Vector3d(p[0], p[1], p[2]);
  table.offset = p[3];
  const geo::TableFrame frame(table, scene.arm_base_right);

  ASSERT_EQ(result.axes.size(), static_cast<size_t>(kFrames - 1)) << "every good pair, not frame 12";
  EXPECT_EQ(result.axes.count(kStart + 12 * kPeriod), 0u);
  for (const auto& [utime, msg] : result.axes) {
    const int f = static_cast<int>((utime - kStart) / kPeriod);
    EXPECT_EQ(msg.num_pairings, f == 7 ? 12 : 9) << "utime " << utime;
    for (int k = 0; k < 3; ++k) {
      const Object& obj = scene.objects[k];
      const nudge::axis3d_t* found = nullptr;
      for (const auto& a : msg.axes)
        if (a.left_index == k && a.right_index == right_order(f, k)) found = &a;
      ASSERT_NE(found, nullptr) << obj.name << " missing at utime " << utime;
      const Eigen::Vector3d table_point = vec(found->table_point);
      EXPECT_LT((frame.to_camera(table_point) - obj.base_right).norm(), 1e-3) << obj.name << " utime " << utime;
      EXPECT_NEAR(table_point.z(), 0.0, 1e-9) << "table points lie on the table";
      EXPECT_LT(found->angle_to_normal, 0.5 * kDeg) << obj.name;
      // The axis ends, in the table frame, lie above the table point.
      const Eigen::Vector3d a = vec(found->point_a), b = vec(found->point_b);
      EXPECT_LT(std::hypot(a.x() - table_point.x(), a.y() - table_point.y()), 2e-3);
      EXPECT_LT(std::hypot(b.x() - table_point.x(), b.y() - table_point.y()), 2e-3);
    }
    for (const auto& a : msg.axes) {
      EXPECT_TRUE(std::isfinite(a.table_point[0]) && std::isfinite(a.angle_to_normal));
      EXPECT_LE(a.angle_to_normal, 15 * kDeg + 1e-9) << "AXES keeps axes within 15 deg of the normal";
    }
  }

  ASSERT_EQ(result.candidates.size(), 1u) << "one answer per request";
  const auto& c = result.candidates.front();
  EXPECT_EQ(c.frames_used, 20);
  EXPECT_EQ(c.utime, kStart + 20 * kPeriod) << "the 20th good pair (frame 12 was skipped)";
  for (const Object& obj : scene.objects) {
    bool near = false;
    for (int i = 0; i < c.num_candidates; ++i) {
      const Eigen::Vector3d pos(c.position[i][0], c.position[i][1], c.position[i][2]);
      near |= (frame.to_camera(pos) - obj.base_right).norm() < 1e-3;
      EXPECT_LE(pos.head<2>().norm(), 0.350 + 1e-9) << "candidates lie in the workspace ring";
      EXPECT_GE(pos.head<2>().norm(), 0.150 - 1e-9) << "candidates lie in the workspace ring";
    }
    EXPECT_EQ(near, obj.in_ring) << obj.name;
  }
  EXPECT_GE(c.intersects, 2 * 20) << "the two ring objects, every frame";
  EXPECT_EQ(c.num_candidates, 2) << "ghost pairings of different objects are not upright on the table";
  EXPECT_EQ(c.cluster_size[0], 20) << "one intersect per frame for a true object";

  EXPECT_EQ(result.errors, 2) << "the NaN line and the wrong image size are counted";
  EXPECT_NE(err.find("line 3 has non-finite values"), std::string::npos) << err;
  EXPECT_NE(err.find("image 320x480 but the calibration is for 640x480"), std::string::npos) << err;
  EXPECT_NE(err.find("unmatched"), std::string::npos) << err;
}

}  // namespace

TEST(TriangulationService, AxesRecoverTheTablePointsAndCandidatesTheRingObjects) {
  const Scene scene;
  ServiceRun service("table");
  geo::save_rig(scene.rig, service.rig);
  write_input_log(scene, service.in);
  ASSERT_EQ(service(table_flags(scene)), 0) << service.command(table_flags(scene)) << "\n" << service.err;
  expect_axes_and_candidates(scene, read_output(service.out), service.err);
}

// Candidates describe the table as it is when they are asked for: stereo pairs taken before the
// request (the arm still moving away, delivered late by a pipeline that lags) are not gathered.
TEST(TriangulationService, CandidatesGatherOnlyPairsTakenAfterTheRequest) {
  const Scene scene;
  ServiceRun service("late");
  geo::save_rig(scene.rig, service.rig);
  const int64_t request_utime = kStart + 10 * kPeriod - 1;
  write_input_log(scene, service.in, request_utime, 10);
  ASSERT_EQ(service(table_flags(scene)), 0) << service.command(table_flags(scene)) << "\n" << service.err;
  const Output output = read_output(service.out);
  const std::string& err = service.err;
  EXPECT_EQ(output.axes.size(), static_cast<size_t>(kFrames - 1));  // AXES for every pair, old or new
  ASSERT_EQ(output.candidates.size(), 1u) << err;
  EXPECT_EQ(output.candidates[0].frames_used, 10);
  // Frames 10..20 without frame 12 (its right image is refused): the tenth pair taken after it.
  EXPECT_EQ(output.candidates[0].utime, kStart + 20 * kPeriod);
  EXPECT_NE(err.find("10 stereo pair(s) taken before the request"), std::string::npos) << err;
}

// An object already explored (sent with the request) gives no candidate: its lines are left out
// of the strongest lines paired. The other ring object's candidate stays.
TEST(TriangulationService, AnExploredObjectsLinesAreNotPaired) {
  const Scene scene;
  const auto p = table_plane_in_right(scene.rig);
  geo::Plane table;
  table.normal = Eigen::Vector3d(p[0], p[1], p[2]);
  table.offset = p[3];
  const geo::TableFrame frame(table, scene.arm_base_right);
  std::vector<const Object*> ring;
  for (const Object& obj : scene.objects)
    if (obj.in_ring) ring.push_back(&obj);
  ASSERT_EQ(ring.size(), 2u);
  ServiceRun service("explored");
  geo::save_rig(scene.rig, service.rig);
  write_input_log(scene, service.in, kStart - 1, 20, {frame.to_table(ring[0]->base_right)});
  ASSERT_EQ(service(table_flags(scene)), 0) << service.command(table_flags(scene)) << "\n" << service.err;
  const Output output = read_output(service.out);
  ASSERT_EQ(output.candidates.size(), 1u) << service.err;
  const auto& c = output.candidates[0];
  ASSERT_EQ(c.num_candidates, 1);
  EXPECT_LT((frame.to_camera(Eigen::Vector3d(c.position[0][0], c.position[0][1], c.position[0][2])) - ring[1]->base_right).norm(), 1e-3);
  EXPECT_NE(service.err.find("leaving out the lines of 1 explored object(s)"), std::string::npos) << service.err;
}

// A request may widen (or narrow) the survey's line tilt for itself: the supervisor's second look.
// A tilt outside (0, 90] degrees is refused by name and nothing is gathered for it.
TEST(TriangulationService, ARequestCarriesItsOwnLineTilt) {
  const Scene scene;
  ServiceRun wide("wide_tilt");
  geo::save_rig(scene.rig, wide.rig);
  write_input_log(scene, wide.in, kStart - 1, 20, {}, 5.0);
  const std::string flags = table_flags(scene) + " --candidate-line-tilt 2";
  ASSERT_EQ(wide(flags), 0) << wide.command(flags) << "\n" << wide.err;
  expect_axes_and_candidates(scene, read_output(wide.out), wide.err);
  EXPECT_NE(wide.err.find("within 5.0"), std::string::npos) << wide.err;
  ServiceRun bad("bad_tilt");
  geo::save_rig(scene.rig, bad.rig);
  write_input_log(scene, bad.in, kStart - 1, 20, {}, 120.0);
  ASSERT_EQ(bad(flags), 0) << bad.command(flags) << "\n" << bad.err;
  EXPECT_TRUE(read_output(bad.out).candidates.empty());
  EXPECT_NE(bad.err.find("max_line_tilt_deg 120"), std::string::npos) << bad.err;
}

TEST(TriangulationService, TableAndArmBaseCanComeFromTheCalibrationFile) {
  const Scene scene;
  ServiceRun service("workspace");
  const auto p = table_plane_in_right(scene.rig);
  geo::Workspace workspace;
  workspace.table = geo::plane_from_coefficients(Eigen::Vector4d(p[0], p[1], p[2], p[3]));
  workspace.arm_base = scene.arm_base_right;
  geo::save_rig(scene.rig, workspace, service.rig);
  const geo::Workspace loaded = geo::load_workspace(service.rig);
  ASSERT_TRUE(loaded.table && loaded.arm_base);
  EXPECT_LT((loaded.table->normal - workspace.table->normal).norm(), 1e-12);
  EXPECT_LT((*loaded.arm_base - scene.arm_base_right).norm(), 1e-12);

  write_input_log(scene, service.in);
  ASSERT_EQ(service(), 0) << service.command() << "\n" << service.err;
  expect_axes_and_candidates(scene, read_output(service.out), service.err);
}

TEST(TriangulationService, WithoutATablePlaneAxesStayInTheCameraFrame) {
  const Scene scene;
  ServiceRun service("no_table");
  geo::save_rig(scene.rig, service.rig);
  write_input_log(scene, service.in);
  ASSERT_EQ(service(), 0) << service.command() << "\n" << service.err;
  const Output result = read_output(service.out);
  const std::string& err = service.err;
  ASSERT_FALSE(result.axes.empty());
  const auto& msg = result.axes.begin()->second;
  const Object& obj = scene.objects[0];
  bool found = false;
  for (const auto& a : msg.axes) {
    if (a.left_index != 0 || a.right_index != right_order(0, 0)) continue;
    found = true;
    EXPECT_TRUE(std::isnan(a.table_point[0]) && std::isnan(a.angle_to_normal));
    // The axis passes within 1 mm of the true base in the right camera's frame.
    const Eigen::Vector3d pa = vec(a.point_a), pb = vec(a.point_b);
    const Eigen::Vector3d d = (pb - pa).normalized();
    EXPECT_LT(((obj.base_right - pa) - (obj.base_right - pa).dot(d) * d).norm(), 1e-3);
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(result.candidates.empty());
  EXPECT_NE(err.find("candidate locations need the table plane"), std::string::npos) << err;
}

TEST(TriangulationService, BadCalibrationAndFlagsAreClearErrors) {
  std::string err;
  const std::string service = bin("nudge-triangulation");
  EXPECT_EQ(run(service + " --calibration /nonexistent/rig.yaml --lcm-url 'file:///dev/null?speed=0'", &err), 1);
  EXPECT_NE(err.find("/nonexistent/rig.yaml: cannot open stereo rig file"), std::string::npos) << err;

  const std::string partial = scratch_dir() + "/triangulation_partial.yaml";
  std::ofstream(partial) << "%YAML:1.0\n---\nleft:\n   image_width: 640\n";
  EXPECT_EQ(run(service + " --calibration " + partial, &err), 1);
  EXPECT_NE(err.find("field 'left.image_height' is missing"), std::string::npos) << err;

  const std::string bad_plane = scratch_dir() + "/triangulation_bad_plane.yaml";
  geo::save_rig(verged_rig(), bad_plane);
  std::ofstream(bad_plane, std::ios::app) << "\ntable_plane: [ 0, 1, 0 ]\n";
  EXPECT_EQ(run(service + " --calibration " + bad_plane, &err), 1);
  EXPECT_NE(err.find("field 'table_plane' must be a list of 4 numbers"), std::string::npos) << err;

  EXPECT_EQ(run(service, &err), 2);
  EXPECT_NE(err.find("--calibration FILE is required"), std::string::npos) << err;
  EXPECT_EQ(run(service + " --calibration x --table-plane 0 0 0 1", &err), 2);
  EXPECT_NE(err.find("normal"), std::string::npos) << err;
  EXPECT_EQ(run(service + " --calibration x --ring-inner 0.4 --ring-outer 0.3", &err), 2);
  // The ring comes from the workspace file the arm reads: a bad one is named, field and all.
  const std::string workspace = scratch_dir() + "/triangulation_workspace.yaml";
  std::ofstream(workspace) << "%YAML:1.0\n---\nbase_yaw_deg: 0\nshoulder_height: 0.33\ntool_length: 0.15\n"
                              "ring_inner: 0.15\ntable_margin: 0.005\n";
  EXPECT_EQ(run(service + " --calibration x --workspace " + workspace, &err), 2);
  EXPECT_NE(err.find(workspace + ": ring_outer: missing"), std::string::npos) << err;
}

// Busy tables (--stereo-check): AXES carry each line's most consistent pairing only, as the
// candidates do; every line paired with every line also gives pairings of two objects' lines.
TEST(TriangulationService, WithTheStereoCheckAxesPairEachLineOnce) {
  const Scene scene;
  ServiceRun service("stereo_check");
  geo::save_rig(scene.rig, service.rig);
  write_input_log(scene, service.in);
  auto line_used_twice = [](const nudge::axes_t& m) {
    std::set<int> left, right;
    for (const auto& a : m.axes)
      if (!left.insert(a.left_index).second || !right.insert(a.right_index).second) return true;
    return false;
  };
  ASSERT_EQ(service(table_flags(scene)), 0) << service.err;
  const Output every = read_output(service.out);
  int frames_with_repeats = 0;
  for (const auto& [utime, m] : every.axes) frames_with_repeats += line_used_twice(m);
  EXPECT_GT(frames_with_repeats, 0) << "without the check a line pairs with several";

  ASSERT_EQ(service(table_flags(scene) + " --stereo-check"), 0) << service.err;
  const Output checked = read_output(service.out);
  ASSERT_EQ(checked.axes.size(), every.axes.size());
  for (const auto& [utime, m] : checked.axes) {
    EXPECT_FALSE(line_used_twice(m)) << "utime " << utime;
    const int f = static_cast<int>((utime - kStart) / kPeriod);
    for (int k = 0; k < 3; ++k) {
      bool found = false;
      for (const auto& a : m.axes) found |= a.left_index == k && a.right_index == right_order(f, k);
      EXPECT_TRUE(found) << scene.objects[k].name << " at utime " << utime;
    }
  }
}

namespace {

// Each object painted as a 24 px wide band of its own colour along its axis' image, on grey: the
// pictures the lines were found in. `right_b` is object B's colour in the right image.
cv::Mat painted(const Scene& scene, bool left, const cv::Scalar& right_b) {
  const cv::Scalar colours[3] = {{40, 40, 200}, {40, 200, 40}, {200, 40, 40}};
  cv::Mat image(kHeight, kWidth, CV_8UC3, cv::Scalar::all(128));
  for (int k = 0; k < 3; ++k) {
    const sym::Line& line = left ? scene.objects[k].left : scene.objects[k].right;
    cv::line(image, line.seg1, line.seg2, k == 1 && !left ? right_b : colours[k], 24);
  }
  return image;
}

// The scene's log with each frame's images before its lines, as the camera and symmetry services
// publish them.
void write_log_with_images(const Scene& scene, const std::string& path, const cv::Scalar& right_b) {
  LogWriter log(path);
  nudge::candidates_request_t request;
  request.utime = kStart - 1;
  request.frames = 10;
  request.lines_per_image = 3;
  request.max_line_tilt_deg = 0;
  request.num_explored = 0;
  log.raw(request.utime, "CANDIDATES_REQUEST", encode(request));
  const cv::Mat left_image = painted(scene, true, {}), right_image = painted(scene, false, right_b);
  for (int f = 0; f < 12; ++f) {
    const int64_t utime = kStart + f * kPeriod;
    std::vector<sym::Line> left, right;
    for (const Object& o : scene.objects) left.push_back(o.left), right.push_back(o.right);
    log.raw(utime, "CAMERA_LEFT", encode(nudge::bus::to_message(left_image, nudge::image_t::FORMAT_BGR8, utime, f, "left")));
    log.raw(utime + 1, "CAMERA_RIGHT",
            encode(nudge::bus::to_message(right_image, nudge::image_t::FORMAT_BGR8, utime, f, "right")));
    log.raw(utime + 10, "SYMMETRY_LEFT", encode(lines_message(left, utime, "left")));
    log.raw(utime + 11, "SYMMETRY_RIGHT", encode(lines_message(right, utime, "right")));
  }
}

bool candidate_near(const Scene& scene, const nudge::candidates_t& c, const Eigen::Vector3d& base_right) {
  const auto p = table_plane_in_right(scene.rig);
  geo::Plane table;
  table.normal = Eigen::Vector3d(p[0], p[1], p[2]);
  table.offset = p[3];
  const geo::TableFrame frame(table, scene.arm_base_right);
  for (int i = 0; i < c.num_candidates; ++i)
    if ((frame.to_camera(Eigen::Vector3d(c.position[i][0], c.position[i][1], c.position[i][2])) - base_right).norm() < 1e-3)
      return true;
  return false;
}

}  // namespace

// --stereo-appearance takes the camera images the lines were found in: an object both cameras see
// in its colour is a candidate; one whose right image shows another colour along its axis (as when
// the right line is another object's) is not; without images no pair is gathered, and it says so.
TEST(TriangulationService, WithTheStereoAppearanceBothImagesMustAgreeAlongTheAxis) {
  const Scene scene;
  ServiceRun service("stereo_appearance");
  geo::save_rig(scene.rig, service.rig);
  const std::string flags = table_flags(scene) + " --stereo-appearance 0.5 --appearance-waived-at-overlap 2";

  write_log_with_images(scene, service.in, {40, 200, 40});  // B green in both
  ASSERT_EQ(service(flags), 0) << service.err;
  Output same = read_output(service.out);
  ASSERT_EQ(same.candidates.size(), 1u) << service.err;
  EXPECT_TRUE(candidate_near(scene, same.candidates[0], scene.objects[0].base_right));
  EXPECT_TRUE(candidate_near(scene, same.candidates[0], scene.objects[1].base_right));

  write_log_with_images(scene, service.in, {200, 40, 200});  // B magenta on the right
  ASSERT_EQ(service(flags), 0) << service.err;
  Output differ = read_output(service.out);
  ASSERT_EQ(differ.candidates.size(), 1u) << service.err;
  EXPECT_TRUE(candidate_near(scene, differ.candidates[0], scene.objects[0].base_right));
  EXPECT_FALSE(candidate_near(scene, differ.candidates[0], scene.objects[1].base_right));
  // The overlap of the two support segments (here the whole axis in both) can waive the check.
  ASSERT_EQ(service(table_flags(scene) + " --stereo-appearance 0.5"), 0) << service.err;
  Output waived = read_output(service.out);
  ASSERT_EQ(waived.candidates.size(), 1u) << service.err;
  EXPECT_TRUE(candidate_near(scene, waived.candidates[0], scene.objects[1].base_right));

  write_input_log(scene, service.in);  // lines only
  ASSERT_EQ(service(flags), 0) << service.err;
  EXPECT_TRUE(read_output(service.out).candidates.empty());
  EXPECT_NE(service.err.find("no CAMERA_LEFT image"), std::string::npos) << service.err;
}
