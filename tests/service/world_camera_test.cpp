// Service tests of the simulated world and the camera's sim backend, each a pure function from
// log to log (LCM file provider):
//  - nudge-world runs ~1 s of simulated time as fast as it can; nudge-camera --source sim renders
//    that log: one stereo pair per SIM_STATE sharing its utime, and the fast symmetry detector
//    finds the upright bottle where the SIM_STATE's ground truth says (2 px, 1 deg); a state of
//    another scene is counted and skipped; a snapshot request gets a 1280x960 pair;
//  - ARM_STATE drives the pusher (the arm's contract) and pushes a cup; SIM_TRUTH_REQUEST gets
//    masks; a bad message is counted and skipped; the same input gives the same output; input
//    stamped in simulated time acts at that time;
//  - bad scenes and flags are usage errors (exit 2) naming the file and field.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "nudge/arm_state_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/image_t.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/sim_truth_request_t.hpp"
#include "nudge/sim_truth_t.hpp"
#include "nudge/snapshot_request_t.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/run_service.hpp"

namespace channel = nudge::bus::channel;

namespace {

using nudge::test::decode;
using nudge::test::encode;
using nudge::test::Event;
using nudge::test::last_heartbeat_errors;
using nudge::test::read_log;
using nudge::test::write_log;

constexpr double kDeg = M_PI / 180.0;
const std::string kBin = nudge::test::bin_dir();

int run(const std::string& cmd) { return nudge::test::run_command(cmd); }

std::string write_scene(const std::string& name, const std::string& objects) {
  const std::string path = testing::TempDir() + "/" + name + ".yaml";
  std::ofstream(path) << "%YAML:1.0\n---\nseed: 3\n"
                      << "table: { type: plain, colour: [0.72, 0.58, 0.42] }\n"
                      << "background: { type: plain, colour: [0.3, 0.4, 0.6] }\n"
                      << "objects:\n"
                      << objects;
  return path;
}

}  // namespace

TEST(WorldCamera, EveryStateBecomesAStereoPairWhoseBottleAxisTheDetectorFinds) {
  const std::string dir = testing::TempDir();
  const std::string scene = write_scene(
      "world_camera_bottle", "  - { kind: bottle, name: bottle, position: [0.25, 0.02], colour: [0.15, 0.3, 0.7] }\n"
                             "  - { kind: cup, name: cup, position: [0.20, -0.15], colour: [0.9, 0.2, 0.2] }\n");
  const std::string world_log = dir + "/world_out.lcmlog", camera_in = dir + "/camera_in.lcmlog",
                    camera_log = dir + "/camera_out.lcmlog";
  std::remove(world_log.c_str());
  std::remove(camera_log.c_str());
  ASSERT_EQ(run(kBin + "/nudge-world --scene " + scene + " --realtime-factor 0 --duration 1.0 --lcm-in memq://" +
                " --lcm-out 'file://" + world_log + "?mode=w'"),
            0);

  // The states, and a snapshot request after the 10th one.
  std::map<int64_t, nudge::sim_state_t> states;
  std::vector<Event> world_events = read_log(world_log), camera_input;
  for (const Event& e : world_events) {
    camera_input.push_back(e);
    if (e.channel != channel::SIM_STATE) continue;
    const auto state = decode<nudge::sim_state_t>(e);
    states[state.utime] = state;
    if (states.size() == 10) {
      // Stamped just after the 10th state (the requester's clock had passed it): the still must
      // wait for the 11th, not show the 10th, which the camera drew last.
      nudge::snapshot_request_t request;
      request.utime = state.utime + 1;
      request.cameras = nudge::snapshot_request_t::CAMERAS_BOTH;
      camera_input.push_back({e.timestamp + 1, channel::CAMERA_SNAPSHOT_REQUEST, encode(request)});
      camera_input.push_back({e.timestamp + 2, channel::CAMERA_SNAPSHOT_REQUEST, encode(request)});  // asked again
    }
    if (states.size() == 5) {  // a state of another scene: reported, counted, no frames
      nudge::sim_state_t other = state;
      other.utime = 999;
      other.objects[0].name = "teapot";
      camera_input.push_back({e.timestamp + 2, channel::SIM_STATE, encode(other)});
    }
  }
  ASSERT_EQ(states.size(), 26u) << "25 Hz over 1 s of simulated time, plus the state at t = 0";
  {  // a right still asked for after the last state: no later state comes, the input ends
    nudge::snapshot_request_t request;
    request.utime = states.rbegin()->first + 1;
    request.cameras = nudge::snapshot_request_t::CAMERAS_RIGHT;
    camera_input.push_back({camera_input.back().timestamp + 1, channel::CAMERA_SNAPSHOT_REQUEST, encode(request)});
  }
  EXPECT_EQ(states.begin()->first, 0);
  EXPECT_EQ(states.rbegin()->first, 1000000);
  write_log(camera_in, camera_input);

  ASSERT_EQ(run(kBin + "/nudge-camera --source sim --scene " + scene + " --snapshots --format png" +
                " --lcm-in 'file://" + camera_in + "?speed=0' --lcm-out 'file://" + camera_log + "?mode=w'"),
            0);
  std::map<int64_t, cv::Mat> left, right;
  std::vector<nudge::image_t> snapshots;
  for (const Event& e : read_log(camera_log)) {
    if (e.channel == channel::CAMERA_LEFT || e.channel == channel::CAMERA_RIGHT) {
      const auto img = decode<nudge::image_t>(e);
      (e.channel == channel::CAMERA_LEFT ? left : right)[img.utime] = nudge::bus::to_mat(img);
    } else if (e.channel == channel::SNAPSHOT_LEFT || e.channel == channel::SNAPSHOT_RIGHT) {
      snapshots.push_back(decode<nudge::image_t>(e));
    }
  }
  EXPECT_EQ(last_heartbeat_errors(read_log(camera_log)), 1) << "the other scene's state is counted";
  ASSERT_EQ(left.size(), states.size()) << "a left frame for every state (and none for the bad one)";
  ASSERT_EQ(right.size(), states.size()) << "a right frame for every state";
  for (const auto& [utime, state] : states) {
    ASSERT_TRUE(left.count(utime) && right.count(utime)) << "left and right share the state's utime " << utime;
    EXPECT_EQ(left[utime].cols, 640);
    EXPECT_EQ(left[utime].rows, 480);
  }
  ASSERT_EQ(snapshots.size(), 3u) << "one still pair for the request asked twice, one right still at the end";
  for (size_t i = 0; i < snapshots.size(); ++i) {
    const auto& s = snapshots[i];
    EXPECT_EQ(s.width, 1280);
    EXPECT_EQ(s.height, 960);
    if (i < 2) {
      EXPECT_EQ(s.utime, std::next(states.begin(), 10)->first) << "the still shows the first state at or after the request";
    } else {
      EXPECT_EQ(s.camera, "right");
      EXPECT_EQ(s.utime, states.rbegin()->first) << "with no later state, the newest there is";
    }
  }

  // Thesis parameters for upright objects in 640x480 frames.
  nudge::symmetry::Params params;
  params.dmin = 25;
  params.dmax = 250;
  params.theta_min_deg = -25;
  params.theta_max_deg = 25;
  params.num_lines = 5;
  // The backdrop's foot is a long straight edge across the image: every pair of its pixels votes
  // for a line perpendicular to it. The thesis' rule against straight lines (§3.2.3) stops that.
  params.once_per_row = true;
  nudge::symmetry::EdgeParams edges;
  edges.blur_sigma = 1.0;
  nudge::symmetry::Detector detector(params, edges);
  for (const int64_t utime : {int64_t{0}, int64_t{520000}, int64_t{1000000}}) {
    const nudge::sim_state_t& state = states.at(utime);
    const auto bottle = std::find_if(state.objects.begin(), state.objects.end(),
                                     [](const nudge::object_state_t& o) { return o.name == "bottle"; });
    ASSERT_NE(bottle, state.objects.end());
    for (int cam = 0; cam < 2; ++cam) {
      const double r = cam == 0 ? bottle->r_left : bottle->r_right;
      const double theta = cam == 0 ? bottle->theta_left : bottle->theta_right;
      const auto result = detector.detect(cam == 0 ? left.at(utime) : right.at(utime));
      // the detected line nearest the true one, by |dR| px + |dtheta| deg
      nudge::symmetry::LineDifference best{1e9, 1e9};
      auto size = [](const nudge::symmetry::LineDifference& d) { return std::abs(d.r) + std::abs(d.theta) / kDeg; };
      for (const auto& line : result.lines) {
        const auto d = nudge::symmetry::line_difference(line.r, line.theta, r, theta);
        if (size(d) < size(best)) best = d;
      }
      EXPECT_NEAR(best.r, 0.0, 2.0) << "camera " << cam << " utime " << utime;
      EXPECT_NEAR(best.theta, 0.0, 1.0 * kDeg) << "camera " << cam << " utime " << utime;
    }
  }
}

TEST(WorldCamera, MotionBlurSmearsAnObjectThatMovedDuringTheFrame) {
  const std::string dir = testing::TempDir();
  const std::string scene = write_scene(
      "world_camera_blur", "  - { kind: bottle, name: bottle, position: [0.25, 0.0], colour: [0.15, 0.3, 0.7] }\n");
  const std::string world_log = dir + "/blur_world.lcmlog", camera_in = dir + "/blur_in.lcmlog";
  std::remove(world_log.c_str());
  ASSERT_EQ(run(kBin + "/nudge-world --scene " + scene + " --realtime-factor 0 --duration 0.04 --lcm-in memq://" +
                " --lcm-out 'file://" + world_log + "?mode=w'"),
            0);
  // Two states: the bottle, then the same bottle 6 cm to the side one frame later.
  std::vector<Event> input;
  for (const Event& e : read_log(world_log)) {
    if (e.channel != channel::SIM_STATE || !input.empty()) continue;
    auto state = decode<nudge::sim_state_t>(e);
    input.push_back({e.timestamp, channel::SIM_STATE, encode(state)});
    state.utime += 40000;
    state.objects[0].pose.position[1] += 0.06;
    input.push_back({e.timestamp + 40000, channel::SIM_STATE, encode(state)});
  }
  ASSERT_EQ(input.size(), 2u);
  write_log(camera_in, input);
  auto left_frames = [&](const std::string& flags) {
    const std::string out = dir + "/blur_out.lcmlog";
    std::remove(out.c_str());
    EXPECT_EQ(run(kBin + "/nudge-camera --source sim --scene " + scene + " --noise 0 --format png " + flags +
                  " --lcm-in 'file://" + camera_in + "?speed=0' --lcm-out 'file://" + out + "?mode=w'"),
              0);
    std::vector<cv::Mat> frames;
    for (const Event& e : read_log(out))
      if (e.channel == channel::CAMERA_LEFT) frames.push_back(nudge::bus::to_mat(decode<nudge::image_t>(e)));
    return frames;
  };
  const auto sharp = left_frames(""), blurred = left_frames("--motion-blur 6");
  ASSERT_EQ(sharp.size(), 2u);
  ASSERT_EQ(blurred.size(), 2u);
  EXPECT_EQ(cv::norm(blurred[0], sharp[0], cv::NORM_INF), 0) << "nothing moved before the first frame";
  // The blurred second frame lies between the two sharp ones: the bottle smeared along its path.
  cv::Mat midway;
  cv::addWeighted(sharp[0], 0.5, sharp[1], 0.5, 0, midway);
  EXPECT_GT(cv::norm(blurred[1], sharp[1], cv::NORM_L1), 1e5);
  EXPECT_GT(cv::norm(blurred[1], sharp[0], cv::NORM_L1), 1e5);
  EXPECT_LT(cv::norm(blurred[1], midway, cv::NORM_L1), cv::norm(sharp[1], midway, cv::NORM_L1));
}

TEST(World, ArmStateDrivesThePusherTruthIsAnsweredAndTheRunIsDeterministic) {
  const std::string dir = testing::TempDir();
  const std::string scene = write_scene("world_push", "  - { kind: cup, name: cup, position: [0.25, 0.0] }\n");
  const std::string in = dir + "/world_push_in.lcmlog";
  // Events at log time T0 + t act at simulated time t.
  const int64_t t0 = 1700000000000000;
  std::vector<Event> input;
  nudge::sim_truth_request_t request;
  request.utime = t0;
  request.without_masks = false;
  input.push_back({t0, channel::SIM_TRUTH_REQUEST, encode(request)});
  // The tool's x axis along +y: the pad sweeps 9 cm along +y, 2 cm above the table, from 10 cm
  // before the cup's axis to 1 cm before it (the cup's base radius is ~3 cm), at 4.5 cm/s.
  const Eigen::Quaterniond tool(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  nudge::arm_state_t arm{};
  for (int k = 0; k <= 200; ++k) {
    arm.utime = t0 + 500000 + 10000 * k;
    arm.end_effector = nudge::bus::to_message(Eigen::Vector3d(0.25, -0.10 + 0.09 * k / 200.0, 0.02), tool);
    arm.joints[0] = 0.1 * k;
    arm.gripper = 0.03;
    input.push_back({arm.utime, channel::ARM_STATE, encode(arm)});
  }
  nudge::arm_state_t bad = arm;  // refused: not a pose
  bad.end_effector.position[2] = std::nan("");
  input.push_back({t0 + 2600000, channel::ARM_STATE, encode(bad)});
  request.utime = t0 + 3000000;
  input.push_back({t0 + 3000000, channel::SIM_TRUTH_REQUEST, encode(request)});
  write_log(in, input);

  std::vector<std::vector<Event>> runs;
  for (int r = 0; r < 2; ++r) {
    const std::string out = dir + "/world_push_out" + std::to_string(r) + ".lcmlog";
    std::remove(out.c_str());
    ASSERT_EQ(run(kBin + "/nudge-world --scene " + scene + " --duration 3.6 --lcm-in 'file://" + in +
                  "?speed=0' --lcm-out 'file://" + out + "?mode=w'"),
              0);
    runs.push_back(read_log(out));
  }
  EXPECT_EQ(last_heartbeat_errors(runs[0]), 1) << "the NaN pose is counted";

  std::map<int64_t, nudge::sim_state_t> states;
  std::vector<nudge::sim_truth_t> truths;
  for (const Event& e : runs[0]) {
    if (e.channel == channel::SIM_STATE) {
      const auto s = decode<nudge::sim_state_t>(e);
      states[s.utime] = s;
    }
    if (e.channel == channel::SIM_TRUTH) truths.push_back(decode<nudge::sim_truth_t>(e));
  }
  ASSERT_EQ(states.size(), 3.6 * 25 + 1);
  // Parked (behind the backdrop) until the first ARM_STATE at t = 0.5 s.
  EXPECT_LT(states.at(480000).pusher.position[0], -0.6);
  EXPECT_DOUBLE_EQ(states.at(480000).joints[0], 0.0);
  // Then at the tool point, facing along the tool's x axis, with the arm's joints and gripper.
  const auto& later = states.at(1000000);
  EXPECT_NEAR(later.pusher.position[0], 0.25, 1e-9);
  EXPECT_NEAR(later.pusher.position[2], 0.02, 1e-9);
  const Eigen::Quaterniond pad = nudge::bus::orientation_of(later.pusher);
  EXPECT_NEAR(pad.angularDistance(tool), 0.0, 1e-9);
  EXPECT_DOUBLE_EQ(later.gripper, -1.0) << "the pad is the tool: no finger opening to report";
  // It stays at the last good pose: the NaN one is skipped.
  const auto& end = states.at(3600000);
  EXPECT_NEAR(end.pusher.position[1], -0.01, 1e-9);
  EXPECT_NEAR(end.joints[0], 20.0, 1e-9);
  // The cup was pushed along +y and stays upright.
  const auto& cup_before = states.at(0).objects.at(0).pose.position;
  const auto& cup_after = end.objects.at(0).pose.position;
  EXPECT_GT(cup_after[1] - cup_before[1], 0.015);
  EXPECT_LT(std::abs(cup_after[0] - cup_before[0]), 0.01);
  EXPECT_GT(end.objects.at(0).axis_direction[2], std::cos(5 * kDeg));

  // Truth at t = 0 and t = 3 s: the state and masks with the cup's label.
  ASSERT_EQ(truths.size(), 2u);
  EXPECT_EQ(truths[0].utime, 0);
  EXPECT_EQ(truths[1].utime, 3000000);
  for (const auto& t : truths) {
    EXPECT_EQ(t.state.utime, t.utime);
    for (const auto* mask : {&t.mask_left, &t.mask_right}) {
      const cv::Mat m = nudge::bus::to_mat(*mask);
      EXPECT_EQ(m.cols, 640);
      EXPECT_GT(cv::countNonZero(m == 1), 1000) << "the cup covers thousands of pixels";
    }
  }

  // Deterministic: the same scene, seed and input give the same states and truth, bit for bit.
  std::vector<const Event*> a, b;
  for (const Event& e : runs[0])
    if (e.channel != channel::HEARTBEAT) a.push_back(&e);
  for (const Event& e : runs[1])
    if (e.channel != channel::HEARTBEAT) b.push_back(&e);
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i]->channel, b[i]->channel) << i;
    ASSERT_TRUE(a[i]->data == b[i]->data) << "message " << i << " on " << a[i]->channel << " differs";
  }
}

// With --tool gripper the arm's tool point carries the gripper and ARM_STATE.gripper is its
// opening: descend open around a bottle, close, lift 5 cm; the bottle goes up with the fingers,
// the same way every run.
TEST(World, WithTheGripperToolArmStateGraspsAndLiftsABottle) {
  const std::string dir = testing::TempDir();
  const std::string scene = write_scene("world_grip", "  - { kind: bottle, name: bottle, position: [0.25, 0.0] }\n");
  const std::string in = dir + "/world_grip_in.lcmlog";
  std::vector<Event> input;
  nudge::arm_state_t arm{};
  arm.end_effector.orientation[0] = 1;  // tool x axis along world x: the fingers close along y
  for (int k = 0; k <= 300; ++k) {  // 100 Hz from t = 0.5 s, stamped in simulated time
    const double t = 0.01 * k;
    arm.utime = 500000 + 10000 * k;
    arm.end_effector.position[0] = 0.25;
    arm.end_effector.position[1] = 0.0;
    // 0-1 s: down from 0.25 to 0.06 m, open; 1-2 s: close; 2-3 s: up 5 cm.
    arm.end_effector.position[2] = t < 1 ? 0.25 - 0.19 * t : t < 2 ? 0.06 : 0.06 + 0.05 * (t - 2);
    arm.gripper = t < 1 ? 0.10 : t < 2 ? 0.10 * (2 - t) : 0.0;
    input.push_back({arm.utime, channel::ARM_STATE, encode(arm)});
  }
  write_log(in, input);
  std::vector<std::vector<uint8_t>> outputs[2];  // SIM_STATE messages of two runs
  for (int r = 0; r < 2; ++r) {
    const std::string out = dir + "/world_grip_out" + std::to_string(r) + ".lcmlog";
    std::remove(out.c_str());
    ASSERT_EQ(run(kBin + "/nudge-world --scene " + scene + " --tool gripper --duration 4 --lcm-in 'file://" + in +
                  "?speed=0' --lcm-out 'file://" + out + "?mode=w'"),
              0);
    for (const Event& e : read_log(out))
      if (e.channel == channel::SIM_STATE) outputs[r].push_back(e.data);
  }
  EXPECT_EQ(outputs[0], outputs[1]) << "deterministic";
  std::map<int64_t, nudge::sim_state_t> states;
  for (const auto& data : outputs[0]) {
    const auto s = decode<nudge::sim_state_t>(Event{0, channel::SIM_STATE, data});
    states[s.utime] = s;
  }
  ASSERT_EQ(states.size(), 4 * 25 + 1);
  const auto& before = states.at(0).objects.at(0).pose.position;
  const auto& closed = states.at(2480000).objects.at(0).pose.position;
  const auto& lifted = states.at(4000000);
  EXPECT_NEAR(closed[2], before[2], 1e-3) << "still on the table after closing";
  EXPECT_NEAR(lifted.objects.at(0).pose.position[2] - before[2], 0.05, 0.005) << "lifted with the fingers";
  EXPECT_NEAR(lifted.objects.at(0).pose.position[0], before[0], 0.005);
  EXPECT_GT(lifted.objects.at(0).axis_direction[2], std::cos(3 * kDeg));
  // Commanded closed (0), the fingers stop on the bottle (70 mm): that is the measured opening a
  // drop check reads, not the command.
  EXPECT_NEAR(lifted.gripper, 0.069, 0.004) << "the fingers' measured opening";
  EXPECT_GT(states.at(480000).gripper, 0.09) << "open before closing";
  EXPECT_EQ(run(kBin + "/nudge-world --scene " + scene + " --tool spoon --duration 1 2>/dev/null"), 2);
}

TEST(World, BadSceneOrFlagsExitWithAUsageErrorNamingTheProblem) {
  const std::string scene = write_scene("world_bad", "  - { kind: teapot, position: [0.25, 0.0] }\n");
  const std::string err = testing::TempDir() + "/world_bad.err";
  EXPECT_EQ(run(kBin + "/nudge-world --scene " + scene + " --lcm-in memq:// 2>" + err), 2);
  std::ifstream f(err);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find(scene + ": objects[0].kind: unknown kind 'teapot'"), std::string::npos) << text;
  EXPECT_EQ(run(kBin + "/nudge-world --lcm-in memq:// 2>/dev/null"), 2) << "no --scene";
  EXPECT_EQ(run(kBin + "/nudge-world --scene " + scene + " --rate 0 2>/dev/null"), 2);
  EXPECT_EQ(run(kBin + "/nudge-camera --source sim --lcm-in memq:// 2>/dev/null"), 2) << "no --scene";
  EXPECT_EQ(run(kBin + "/nudge-camera --source sim --scene " + scene + " --lcm-in memq:// 2>/dev/null"), 2);
}

TEST(World, InputStampedInSimulatedTimeActsAtThatTimeAndOtherClocksAreRefused) {
  const std::string dir = testing::TempDir();
  const std::string scene = write_scene("world_sim_clock", "  - { kind: cup, name: cup, position: [0.25, 0.0] }\n");
  const std::string in = dir + "/world_sim_clock_in.lcmlog", out = dir + "/world_sim_clock_out.lcmlog";
  std::remove(out.c_str());
  // An arm on --clock sim stamps ARM_STATE with SIM_STATE's utime: the first one at t = 0.5 s.
  nudge::arm_state_t arm{};
  arm.end_effector.position[0] = 0.25;
  arm.end_effector.position[1] = -0.2;
  arm.end_effector.position[2] = 0.05;
  arm.end_effector.orientation[0] = 1;
  std::vector<Event> input;
  for (int k = 0; k < 10; ++k) {
    arm.utime = 500000 + 10000 * k;
    input.push_back({1700000000000000 + k, channel::ARM_STATE, encode(arm)});
  }
  nudge::sim_truth_request_t wall_clock;  // a wall-clock stamp among simulated ones: refused
  wall_clock.utime = 1700000000000000;
  wall_clock.without_masks = true;
  input.push_back({1700000000000100, channel::SIM_TRUTH_REQUEST, encode(wall_clock)});
  write_log(in, input);
  ASSERT_EQ(run(kBin + "/nudge-world --scene " + scene + " --duration 1 --lcm-in 'file://" + in +
                "?speed=0' --lcm-out 'file://" + out + "?mode=w' 2>/dev/null"),
            0);
  const auto events = read_log(out);
  std::map<int64_t, nudge::sim_state_t> states;
  for (const Event& e : events) {
    EXPECT_NE(e.channel, channel::SIM_TRUTH) << "the wall-clock request is not answered";
    if (e.channel == channel::SIM_STATE) {
      const auto s = decode<nudge::sim_state_t>(e);
      states[s.utime] = s;
    }
  }
  ASSERT_EQ(states.size(), 26u);
  EXPECT_LT(states.at(480000).pusher.position[0], -0.6) << "parked before t = 0.5 s";
  EXPECT_NEAR(states.at(520000).pusher.position[1], -0.2, 1e-12) << "at the tool point from t = 0.5 s";
  EXPECT_EQ(last_heartbeat_errors(events), 1);
}

TEST(World, ArmJointsDriveTheSimulatedPumaWhichTheCameraDraws) {
  const std::string dir = testing::TempDir();
  const std::string objects = "  - { kind: cup, name: cup, position: [0.25, 0.15] }\n";
  const std::string scene = write_scene("world_arm", objects + "arm: { present: 1, joints_deg: [0, 90, -90, 0, 0, 0] }\n");
  const std::string armless = write_scene("world_no_arm", objects);
  const std::string in = dir + "/world_arm_in.lcmlog";
  const int64_t t0 = 1700000000000000;
  // From straight up to leaning out over the table, commanded at 0.5 s.
  const double target[6] = {-30 * kDeg, 20 * kDeg, -120 * kDeg, 10 * kDeg, 40 * kDeg, 0};
  nudge::arm_state_t arm{};
  arm.utime = t0 + 500000;
  arm.end_effector.position[0] = -1.0;  // the tool pad parked far away: only the joints matter here
  arm.end_effector.orientation[0] = 1;
  for (int j = 0; j < 6; ++j) arm.joints[j] = target[j];
  write_log(in, {{arm.utime, channel::ARM_STATE, encode(arm)}});
  const std::string out = dir + "/world_arm_out.lcmlog";
  std::remove(out.c_str());
  ASSERT_EQ(run(kBin + "/nudge-world --scene " + scene + " --duration 2.5 --rate 10 --lcm-in 'file://" + in +
                "?speed=0' --lcm-out 'file://" + out + "?mode=w'"),
            0);
  std::vector<nudge::sim_state_t> states;
  for (const Event& e : read_log(out))
    if (e.channel == channel::SIM_STATE) states.push_back(decode<nudge::sim_state_t>(e));
  ASSERT_GE(states.size(), 20u);
  EXPECT_NEAR(states.front().joints[1], 90 * kDeg, 1e-6) << "straight up before the command";
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(states.back().joints[j], target[j], 0.1 * kDeg) << "joint " << j + 1;
  const auto at = [&](double t) {  // the state nearest simulated time t
    return *std::min_element(states.begin(), states.end(), [&](const auto& a, const auto& b) {
      return std::abs(a.utime - t * 1e6) < std::abs(b.utime - t * 1e6);
    });
  };
  EXPECT_GT(std::abs(at(0.6).joints[1] - target[1]), 1 * kDeg) << "the servos take time: not there 0.1 s later";
  // The pad rides on the simulated flange: SIM_STATE.pusher is the tool point of the joints it
  // reports (robot library's kinematics, shoulder 0.33 m above the table), not ARM_STATE's pose.
  nudge::robot::JointVector q;
  for (int j = 0; j < 6; ++j) q[j] = states.back().joints[j];
  const Eigen::Vector3d tool =
      nudge::robot::forward_kinematics(nudge::robot::puma260(), q).translation() + Eigen::Vector3d(0, 0, 0.33);
  const Eigen::Vector3d pad(states.back().pusher.position[0], states.back().pusher.position[1],
                            states.back().pusher.position[2]);
  EXPECT_LT((pad - tool).norm(), 2e-3) << "pad " << pad.transpose() << ", tool point " << tool.transpose();

  // The camera draws the arm where SIM_STATE puts it: its frames differ from those of the same
  // scene without an arm.
  auto render_last = [&](const std::string& scene_file, const std::string& name) {
    const std::string frames = dir + "/" + name + "_frames.lcmlog";
    std::remove(frames.c_str());
    EXPECT_EQ(run(kBin + "/nudge-camera --source sim --scene " + scene_file + " --lcm-in 'file://" + out +
                  "?speed=0' --lcm-out 'file://" + frames + "?mode=w'"),
              0);
    cv::Mat last;
    for (const Event& e : read_log(frames))
      if (e.channel == channel::CAMERA_RIGHT) last = nudge::bus::to_mat(decode<nudge::image_t>(e));
    return last;
  };
  const cv::Mat with = render_last(scene, "arm"), without = render_last(armless, "no_arm");
  ASSERT_FALSE(with.empty());
  ASSERT_EQ(with.size(), without.size());
  cv::Mat diff;
  cv::absdiff(with, without, diff);
  if (diff.channels() == 3) cv::cvtColor(diff, diff, cv::COLOR_BGR2GRAY);
  EXPECT_GT(cv::countNonZero(diff > 30), 2000) << "the arm shows in the right camera";
}
