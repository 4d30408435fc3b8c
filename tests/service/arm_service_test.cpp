// Service test: nudge-arm as a pure function from log to log (file provider, speed=0, clock =
// the log's timestamps). Input logs hold ARM_COMMAND requests and HEARTBEAT traffic that moves
// the clock; the output's ARM_STATE stream is checked against the robot library's kinematics.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>
#include <vector>

#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/heartbeat_t.hpp"
#include "nudge/robot/kinematics.hpp"
#include "nudge/robot/motions.hpp"
#include "nudge/robot/puma260.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/run_service.hpp"

namespace channel = nudge::bus::channel;

namespace {

using nudge::test::encode;
using nudge::test::run_from_log;
using nudge::test::temp_path;

using nudge::arm_command_t;
using nudge::arm_state_t;
using nudge::heartbeat_t;

constexpr double kBaseHeight = 0.33;  // the service's default --base-height
constexpr int64_t kStart = 1000000;   // log time of the first event, microseconds
constexpr int64_t kSecond = 1000000;
// LCM's constants are declared but not defined: copies, so gtest may take their address.
constexpr int kMoving = arm_state_t::MOTION_MOVING, kDone = arm_state_t::MOTION_DONE,
              kRefused = arm_state_t::MOTION_REFUSED, kStopped = arm_state_t::MOTION_STOPPED;

// An input log under construction: events must be added in time order.
class InputLog {
 public:
  explicit InputLog(const std::string& path) : log_(path) {}

  void raw(int64_t utime, const std::string& channel, const std::vector<uint8_t>& bytes) {
    log_.raw(utime, channel, bytes);
  }
  void command(int64_t utime, arm_command_t cmd) {
    cmd.utime = utime;
    cmd.num_joints = static_cast<int32_t>(cmd.joints.size());
    log_.write(utime, "ARM_COMMAND", cmd);
  }
  void heartbeat(int64_t utime, const std::string& service, int8_t state = heartbeat_t::STATE_RUNNING) {
    heartbeat_t hb{};
    hb.utime = utime;
    hb.service = service;
    hb.instance = service;
    hb.state = state;
    log_.write(utime, "HEARTBEAT", hb);
  }
  // Other services' heartbeats every 100 ms over [from, to): traffic that moves the log clock.
  void traffic(int64_t from, int64_t to, const std::string& service = "world") {
    for (int64_t t = from; t < to; t += 100000) heartbeat(t, service);
  }

 private:
  nudge::test::LogWriter log_;
};

struct Output {
  std::vector<arm_state_t> states;
  int64_t errors = -1;  // from the last heartbeat
};

Output run_service(const std::string& in, const std::string& out, const std::string& flags = "") {
  const auto run = run_from_log("nudge-arm", "--backend fake" + flags, in, out);
  EXPECT_EQ(run.exit_code, 0) << run.command;
  return {nudge::test::messages_on<arm_state_t>(run.output, "ARM_STATE"), nudge::test::last_heartbeat_errors(run.output)};
}

std::vector<arm_state_t> of_command(const std::vector<arm_state_t>& states, int64_t seq) {
  std::vector<arm_state_t> out;
  for (const auto& s : states)
    if (s.command_seq == seq) out.push_back(s);
  return out;
}

Eigen::Vector3d position(const arm_state_t& s) {
  return nudge::bus::position_of(s.end_effector);
}

// The tool point from the published joints, by the robot library's kinematics, in the world.
Eigen::Vector3d fk_world(const arm_state_t& s) {
  nudge::robot::JointVector q;
  for (int j = 0; j < 6; ++j) q[j] = s.joints[j];
  return nudge::robot::forward_kinematics(nudge::robot::puma260(), q).translation() +
         Eigen::Vector3d(0, 0, kBaseHeight);
}

arm_command_t tool_down_pose_command(int64_t seq, const Eigen::Vector3d& p, double yaw) {
  arm_command_t c{};
  c.seq = seq;
  c.command = arm_command_t::COMMAND_MOVE_POSE;
  c.target = nudge::bus::to_message(p, Eigen::Quaterniond(nudge::robot::tool_down_orientation(yaw)));
  return c;
}

arm_command_t nudge_command(int64_t seq, const Eigen::Vector3d& target, const Eigen::Vector3d& direction) {
  arm_command_t c{};
  c.seq = seq;
  c.command = arm_command_t::COMMAND_NUDGE;
  for (int i = 0; i < 3; ++i) {
    c.target.position[i] = target[i];
    c.direction[i] = direction[i];
  }
  c.target.orientation[0] = 1;
  return c;
}

}  // namespace

TEST(ArmService, MovesNudgesRefusesAndSkipsMalformedCommands) {
  const std::string in = temp_path("arm_in.lcmlog"), out = temp_path("arm_out.lcmlog");
  const Eigen::Vector3d pose_target(0.25, 0.05, 0.12);
  const Eigen::Vector3d nudge_target(0.25, 0.0, 0.0), push(0.0, 1.0, 0.0);
  {
    InputLog log(in);
    log.command(kStart, tool_down_pose_command(1, pose_target, 0.5));
    log.traffic(kStart + 50000, kStart + 10 * kSecond);
    log.command(kStart + 10 * kSecond, tool_down_pose_command(2, {0.60, 0.0, 0.10}, 0.0));  // too far
    log.command(kStart + 10 * kSecond + 10, nudge_command(3, {0.08, 0.02, 0.0}, push));   // inside the ring
    arm_command_t nudge = nudge_command(4, nudge_target, push);
    nudge.height = 0.02;
    log.command(kStart + 10 * kSecond + 20, nudge);
    log.traffic(kStart + 10 * kSecond + 50000, kStart + 40 * kSecond);
    arm_command_t folded{};  // joints within their limits, but the tool folded into the pedestal
    folded.seq = 5;
    folded.command = arm_command_t::COMMAND_MOVE_JOINTS;
    for (double deg : {0.0, 0.0, -215.0, 90.0, -90.0, 0.0}) folded.joints.push_back(deg * M_PI / 180);
    log.command(kStart + 40 * kSecond - 10, folded);
    log.raw(kStart + 40 * kSecond, channel::ARM_COMMAND, {1, 2, 3});  // does not decode
    arm_command_t three_joints{};
    three_joints.seq = 6;
    three_joints.command = arm_command_t::COMMAND_MOVE_JOINTS;
    three_joints.joints = {0.1, 0.2, 0.3};
    log.command(kStart + 40 * kSecond + 10, three_joints);
    arm_command_t unknown{};
    unknown.seq = 7;
    unknown.command = 42;
    log.command(kStart + 40 * kSecond + 20, unknown);
    arm_command_t crawl = tool_down_pose_command(8, pose_target, 0.5);
    crawl.speed_scale = 1e-9;  // would take years: refused
    log.command(kStart + 40 * kSecond + 30, crawl);
    log.traffic(kStart + 40 * kSecond + 50000, kStart + 41 * kSecond);
  }
  const Output output = run_service(in, out);
  ASSERT_FALSE(output.states.empty());

  // Message time makes the output a function of the input: a second run gives the same states.
  const Output again = run_service(in, out);
  ASSERT_EQ(again.states.size(), output.states.size());
  for (size_t i = 0; i < output.states.size(); ++i) {
    ASSERT_EQ(encode(again.states[i]), encode(output.states[i])) << "state " << i;
  }

  // Periodic states at 100 Hz of log time, in order.
  int periodic = 0;
  for (size_t i = 1; i < output.states.size(); ++i) {
    ASSERT_GE(output.states[i].utime, output.states[i - 1].utime);
    if (output.states[i].utime - output.states[i - 1].utime == 10000) ++periodic;
  }
  EXPECT_GT(periodic, 3900);

  // 1: reachable pose, reached.
  const auto move = of_command(output.states, 1);
  ASSERT_FALSE(move.empty());
  EXPECT_EQ(move.front().motion + 0, kMoving);
  EXPECT_EQ(move.back().motion + 0, kDone) << move.back().last_error;
  EXPECT_LT((fk_world(move.back()) - pose_target).norm(), 1e-3);
  EXPECT_LT((position(move.back()) - pose_target).norm(), 1e-3);
  EXPECT_NEAR(move.back().end_effector.orientation[0] * move.back().end_effector.orientation[0], 0.0, 1e-6)
      << "tool pointing down: w = 0";

  // 2, 3: refused with reasons.
  const auto far = of_command(output.states, 2);
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].motion + 0, kRefused);
  EXPECT_NE(far[0].last_error.find("reach"), std::string::npos) << far[0].last_error;
  const auto inside = of_command(output.states, 3);
  ASSERT_EQ(inside.size(), 1u);
  EXPECT_EQ(inside[0].motion + 0, kRefused);
  EXPECT_NE(inside[0].last_error.find("ring"), std::string::npos) << inside[0].last_error;

  // 4: the nudge, P0 -> P1 -> P2 -> P1 -> P0 with the tool above the table.
  const auto nudge = of_command(output.states, 4);
  ASSERT_GT(nudge.size(), 300u) << "a few seconds of states at 100 Hz";
  EXPECT_EQ(nudge.back().motion + 0, kDone) << nudge.back().last_error;
  const nudge::robot::NudgeParams defaults;
  const Eigen::Vector3d up(0, 0, 1);
  const Eigen::Vector3d p0 = nudge_target + defaults.approach_height * up - defaults.start_distance * push;
  const Eigen::Vector3d p1 = nudge_target + 0.02 * up - defaults.start_distance * push;
  const Eigen::Vector3d p2 = nudge_target + 0.02 * up - defaults.stop_distance * push;
  const std::vector<Eigen::Vector3d> keys{p0, p1, p2, p1, p0};
  size_t next_key = 0;
  double lowest = 1e9;
  for (const auto& s : nudge) {
    const Eigen::Vector3d p = position(s);
    EXPECT_LT((p - fk_world(s)).norm(), 1e-6);
    lowest = std::min(lowest, p.z());
    if (next_key > 0) {
      EXPECT_LT((p - nudge_target).dot(push), -defaults.stop_distance + 1e-3) << "never past P2";
    }
    if (next_key < keys.size() && (p - keys[next_key]).norm() < 1e-3) ++next_key;
  }
  EXPECT_EQ(next_key, keys.size()) << "passed P0, P1, P2, P1, P0 in order";
  EXPECT_GT(lowest, 0.02 - 1e-3);
  EXPECT_LT(lowest, 0.02 + 1e-3);

  // 5: a self-colliding joint target is refused, whatever the backend.
  const auto folded = of_command(output.states, 5);
  ASSERT_FALSE(folded.empty());
  EXPECT_EQ(folded.front().motion + 0, kRefused);
  EXPECT_NE(folded.front().last_error.find("self-collision"), std::string::npos) << folded.front().last_error;

  // 6, 7, 8: malformed content is refused and counted with the undecodable message.
  for (int64_t seq : {6, 7, 8}) {
    const auto bad = of_command(output.states, seq);
    ASSERT_FALSE(bad.empty()) << seq;
    EXPECT_EQ(bad.front().motion + 0, kRefused);
    EXPECT_FALSE(bad.front().last_error.empty());
  }
  EXPECT_EQ(output.errors, 4);
}

namespace {

nudge::robot::JointVector home_joints() {
  nudge::robot::SafetyConfig safety;
  safety.table_z = -kBaseHeight;
  return nudge::robot::home_configuration(nudge::robot::puma260(), safety).q;
}

arm_command_t joints_command(int64_t seq, const nudge::robot::JointVector& q, double speed_scale) {
  arm_command_t c{};
  c.seq = seq;
  c.command = arm_command_t::COMMAND_MOVE_JOINTS;
  c.joints.assign(q.data(), q.data() + 6);
  c.speed_scale = speed_scale;
  return c;
}

arm_command_t simple_command(int64_t seq, int8_t code) {
  arm_command_t c{};
  c.seq = seq;
  c.command = code;
  return c;
}

const arm_state_t* first_with(const std::vector<arm_state_t>& states, int64_t seq, int motion) {
  for (const auto& s : states)
    if (s.command_seq == seq && s.motion == motion) return &s;
  return nullptr;
}

}  // namespace

TEST(ArmService, StopsWhenTheSupervisorGoesQuietOrStopsAndOnCommand) {
  const std::string in = temp_path("arm_watchdog_in.lcmlog"), out = temp_path("arm_watchdog_out.lcmlog");
  const nudge::robot::JointVector home = home_joints();
  nudge::robot::JointVector turned = home;
  turned[0] += 60 * M_PI / 180;  // a slow swing about the base axis: stays in the ring
  {
    InputLog log(in);
    for (int64_t t = kStart; t <= kStart + kSecond; t += 200000) {
      log.heartbeat(t, "supervisor");
      log.heartbeat(t + 100000, "world");
      if (t == kStart + 400000) log.command(t + 100001, joints_command(1, turned, 0.2));
    }
    log.traffic(kStart + kSecond + 100000, kStart + 3 * kSecond);
    log.command(kStart + 3 * kSecond, joints_command(2, turned, 0.2));  // refused: no supervisor
    log.traffic(kStart + 3 * kSecond + 100000, kStart + 4 * kSecond);
    for (int64_t t = kStart + 4 * kSecond; t < kStart + 7500000; t += 100000) {
      log.heartbeat(t, t % 200000 ? "world" : "supervisor");
      if (t == kStart + 4100000) log.command(t + 1, joints_command(3, turned, 0.2));
      if (t == kStart + 5 * kSecond) log.command(t + 1, simple_command(4, arm_command_t::COMMAND_HOME));
      if (t == kStart + 6 * kSecond) log.command(t + 1, simple_command(5, arm_command_t::COMMAND_STOP));
      if (t == kStart + 7 * kSecond) log.command(t + 1, simple_command(6, arm_command_t::COMMAND_HOME));
    }
    log.heartbeat(kStart + 7500000, "supervisor", heartbeat_t::STATE_STOPPING);
    log.traffic(kStart + 7600000, kStart + 9 * kSecond);
  }
  const Output output = run_service(in, out);

  // Lost heartbeat: stopped 1.5 s (the default timeout) after the last beat, mid-swing.
  const arm_state_t* lost = first_with(output.states, 1, kStopped);
  ASSERT_NE(lost, nullptr);
  EXPECT_EQ(lost->utime, kStart + kSecond + 1500000 + 1);
  EXPECT_NE(lost->last_error.find("supervisor heartbeat lost"), std::string::npos) << lost->last_error;
  EXPECT_GT(lost->joints[0], home[0] + 0.05);
  EXPECT_LT(lost->joints[0], turned[0] - 0.05);
  for (const auto& s : of_command(output.states, 1)) {
    if (s.utime > lost->utime) {
      EXPECT_EQ(s.joints[0], lost->joints[0]) << "held still";
    }
  }
  const auto refused = of_command(output.states, 2);
  ASSERT_FALSE(refused.empty());
  EXPECT_EQ(refused.front().motion + 0, kRefused);
  EXPECT_NE(refused.front().last_error.find("supervisor"), std::string::npos) << refused.front().last_error;

  // Back: a new command runs, a second one is refused as busy while the first goes on.
  ASSERT_NE(first_with(output.states, 3, kMoving), nullptr);
  const arm_state_t* busy = first_with(output.states, 4, kRefused);
  ASSERT_NE(busy, nullptr);
  EXPECT_NE(busy->last_error.find("busy"), std::string::npos) << busy->last_error;
  const arm_state_t* still_moving = nullptr;
  for (const auto& s : output.states)
    if (s.utime > busy->utime && s.command_seq == 3) {
      still_moving = &s;
      break;
    }
  ASSERT_NE(still_moving, nullptr);
  EXPECT_EQ(still_moving->motion + 0, kMoving);

  // COMMAND_STOP.
  const arm_state_t* stopped = first_with(output.states, 5, kStopped);
  ASSERT_NE(stopped, nullptr);
  EXPECT_NE(stopped->last_error.find("COMMAND_STOP"), std::string::npos) << stopped->last_error;

  // A supervisor announcing that it stops counts as lost at once.
  ASSERT_NE(first_with(output.states, 6, kMoving), nullptr);
  const arm_state_t* stopping = first_with(output.states, 6, kStopped);
  ASSERT_NE(stopping, nullptr);
  EXPECT_EQ(stopping->utime, kStart + 7500000);
  EXPECT_NE(stopping->last_error.find("supervisor is stopping"), std::string::npos) << stopping->last_error;
  EXPECT_EQ(output.errors, 0);
}

TEST(ArmService, GraspsRotatesPlacesAndParksOnTheSimBackend) {
  const std::string in = temp_path("arm_grasp_in.lcmlog"), out = temp_path("arm_grasp_out.lcmlog");
  const Eigen::Vector3d grasp_at(0.25, 0.0, 0.0), place_at(0.22, 0.06, 0.0);
  const double grasp_height = 0.05;
  {
    InputLog log(in);
    arm_command_t grasp = simple_command(1, arm_command_t::COMMAND_GRASP);
    for (int i = 0; i < 3; ++i) grasp.target.position[i] = grasp_at[i];
    grasp.height = grasp_height;
    log.command(kStart, grasp);
    log.traffic(kStart + 100000, kStart + 20 * kSecond);
    arm_command_t rotate = simple_command(2, arm_command_t::COMMAND_ROTATE_WRIST);
    rotate.angle = 30 * M_PI / 180;
    log.command(kStart + 20 * kSecond, rotate);
    log.traffic(kStart + 20 * kSecond + 100000, kStart + 25 * kSecond);
    arm_command_t place = grasp;
    place.seq = 3;
    place.command = arm_command_t::COMMAND_PLACE;
    for (int i = 0; i < 3; ++i) place.target.position[i] = place_at[i];
    log.command(kStart + 25 * kSecond, place);
    log.traffic(kStart + 25 * kSecond + 100000, kStart + 45 * kSecond);
    log.command(kStart + 45 * kSecond, simple_command(4, arm_command_t::COMMAND_HOME));
    log.traffic(kStart + 45 * kSecond + 100000, kStart + 55 * kSecond);
  }
  const auto run = run_from_log("nudge-arm", "--backend sim", in, out);
  ASSERT_EQ(run.exit_code, 0) << run.command;
  const auto states = nudge::test::messages_on<arm_state_t>(run.output, "ARM_STATE");
  const nudge::robot::GraspParams grasp_params;

  const auto grasp = of_command(states, 1);
  ASSERT_FALSE(grasp.empty());
  ASSERT_EQ(grasp.back().motion + 0, kDone) << grasp.back().last_error;
  double lowest = 1e9;
  bool gripper_in_between = false;
  for (const auto& s : grasp) {
    lowest = std::min(lowest, position(s).z());
    gripper_in_between = gripper_in_between || (s.gripper > 0.01 && s.gripper < 0.09);
  }
  EXPECT_NEAR(lowest, grasp_height, 1e-3);
  EXPECT_TRUE(gripper_in_between) << "the simulated gripper closes over time";
  EXPECT_EQ(grasp.back().gripper, 0.0);
  EXPECT_LT((position(grasp.back()) - (grasp_at + grasp_params.lift_height * Eigen::Vector3d::UnitZ())).norm(), 1e-3);

  const auto rotate = of_command(states, 2);
  ASSERT_EQ(rotate.back().motion + 0, kDone) << rotate.back().last_error;
  EXPECT_NEAR(rotate.back().joints[5] - grasp.back().joints[5], 30 * M_PI / 180, 1e-9);

  const auto place = of_command(states, 3);
  ASSERT_EQ(place.back().motion + 0, kDone) << place.back().last_error;
  EXPECT_NEAR(place.back().gripper, 0.10, 1e-9);
  EXPECT_LT((position(place.back()) - (place_at + grasp_params.approach_height * Eigen::Vector3d::UnitZ())).norm(), 1e-3);

  const auto home = of_command(states, 4);
  ASSERT_EQ(home.back().motion + 0, kDone) << home.back().last_error;
  for (int j = 0; j < 6; ++j) EXPECT_NEAR(home.back().joints[j], home_joints()[j], 1e-9) << j;
}

TEST(ArmService, RequiredSupervisorAndBaseFrameFlags) {
  const std::string in = temp_path("arm_flags_in.lcmlog"), out = temp_path("arm_flags_out.lcmlog");
  const Eigen::Vector3d target(0.0, 0.25, 0.10);  // world frame
  {
    InputLog log(in);
    log.command(kStart, tool_down_pose_command(1, target, 0.0));  // refused: no supervisor yet
    log.heartbeat(kStart + 100000, "supervisor");
    log.command(kStart + 100001, tool_down_pose_command(2, target, 0.0));
    for (int64_t t = kStart + 200000; t < kStart + 10 * kSecond; t += 200000) log.heartbeat(t, "supervisor");
  }
  // The base turned 90 deg and standing 0.35 m above the table: world poses still come out right.
  const Output output = run_service(in, out, " --require-supervisor --base-yaw-deg 90 --base-height 0.35");
  const auto first = of_command(output.states, 1);
  ASSERT_FALSE(first.empty());
  EXPECT_EQ(first.front().motion + 0, kRefused);
  EXPECT_NE(first.front().last_error.find("--require-supervisor"), std::string::npos) << first.front().last_error;
  const auto second = of_command(output.states, 2);
  ASSERT_FALSE(second.empty());
  ASSERT_EQ(second.back().motion + 0, kDone) << second.back().last_error;
  EXPECT_LT((position(second.back()) - target).norm(), 1e-3);
}

// The workspace file sets the base and the ring; a flag given overrides its field.
TEST(ArmService, WorkspaceFileAndItsOverrides) {
  const std::string in = temp_path("arm_ws_in.lcmlog"), out = temp_path("arm_ws_out.lcmlog");
  const std::string workspace = temp_path("arm_workspace.yaml");
  {
    std::ofstream file(workspace);
    file << "%YAML:1.0\n---\nbase_yaw_deg: 90\nshoulder_height: 0.35\ntool_length: 0.15\n"
            "ring_inner: 0.15\nring_outer: 0.27\ntable_margin: 0.005\n";
  }
  const Eigen::Vector3d target(0.0, 0.30, 0.10);  // world frame: 0.30 m from the base axis
  {
    InputLog log(in);
    log.command(kStart, tool_down_pose_command(1, target, 0.0));
    log.traffic(kStart + 100000, kStart + 10 * kSecond);
  }
  const Output narrow = run_service(in, out, " --workspace " + workspace);
  const auto refused = of_command(narrow.states, 1);
  ASSERT_FALSE(refused.empty());
  EXPECT_EQ(refused.back().motion + 0, kRefused);
  EXPECT_NE(refused.back().last_error.find("0.150-0.270 m workspace ring"), std::string::npos)
      << refused.back().last_error;

  const Output wider = run_service(in, out, " --workspace " + workspace + " --ring-outer 0.35");
  const auto moved = of_command(wider.states, 1);
  ASSERT_FALSE(moved.empty());
  ASSERT_EQ(moved.back().motion + 0, kDone) << moved.back().last_error;
  EXPECT_LT((position(moved.back()) - target).norm(), 1e-3);  // the file's turned, higher base

  const std::string bin = nudge::test::bin_dir() + "/nudge-arm";
  EXPECT_EQ(nudge::test::run_command(bin + " --workspace " + temp_path("no_such_workspace.yaml") + " 2>/dev/null"), 2);
}

TEST(ArmService, ClockSimFollowsTheSimulatedTimeOfSimState) {
  const std::string in = temp_path("arm_sim_in.lcmlog"), out = temp_path("arm_sim_out.lcmlog");
  const Eigen::Vector3d target(0.25, 0.05, 0.12);
  auto sim_state = [](int64_t utime) {
    nudge::sim_state_t s{};
    s.utime = utime;
    s.gripper = utime < 3 * kSecond ? -1.0 : 0.05;  // the world's fingers: the pad first, then 5 cm open
    return s;
  };
  {
    InputLog log(in);
    // Log timestamps far apart from the simulated times: only SIM_STATE's utime counts.
    log.raw(kStart, channel::SIM_STATE, encode(sim_state(0)));
    log.command(kStart + 1, tool_down_pose_command(1, target, 0.5));
    for (int i = 1; i <= 150; ++i) log.raw(kStart + 1 + i, channel::SIM_STATE, encode(sim_state(i * kSecond / 30)));
    log.raw(kStart + 200, channel::SIM_STATE, encode(sim_state(60 * kSecond)));  // the world jumps a minute
  }
  const Output output = run_service(in, out, " --clock sim");
  const auto move = of_command(output.states, 1);
  ASSERT_FALSE(move.empty());
  EXPECT_EQ(move.back().motion + 0, kDone) << move.back().last_error;
  EXPECT_LT((position(move.back()) - target).norm(), 1e-3);
  const arm_state_t* done = first_with(output.states, 1, kDone);
  ASSERT_NE(done, nullptr);
  EXPECT_GT(done->utime, kSecond);  // the move takes seconds of simulated time
  EXPECT_LT(done->utime, 5 * kSecond);
  EXPECT_EQ(done->utime % 10000, 0) << "on the 100 Hz grid of simulated time";
  // After the jump only the last second (the default --max-catch-up) is published.
  int64_t after_five_seconds = 0;
  for (const auto& s : output.states) after_five_seconds += s.utime > 5 * kSecond;
  EXPECT_EQ(after_five_seconds, 101);
  // The fake driver has no finger sensor; the sim backend's sensor is the world:
  // ARM_STATE.gripper_measured follows SIM_STATE's fingers.
  for (const auto& s : output.states) ASSERT_DOUBLE_EQ(s.gripper_measured, -1.0);
  const Output simulated = run_service(in, out, " --clock sim --backend sim");
  ASSERT_FALSE(simulated.states.empty());
  EXPECT_DOUBLE_EQ(simulated.states.front().gripper_measured, -1.0);
  EXPECT_DOUBLE_EQ(simulated.states.back().gripper_measured, 0.05);
}

TEST(ArmService, BadFlagsAreRefusedWithAUsageError) {
  const std::string bin = nudge::test::bin_dir() + "/nudge-arm";
  for (const std::string args : {" --backend hardware", " --clock moon", " --rate 0", " --speed-scale 2",
                                 " --initial-joints 0 0 0 0 0 400", " --base-height -1", " --no-such-flag"}) {
    EXPECT_EQ(nudge::test::run_command(bin + args + " 2>/dev/null"), 2) << args;
  }
}
