// Integration: the arm service nudges a cup in the simulated world with the simulated PUMA 260.
// nudge-world (a scene with the arm, the pad riding on its flange) and nudge-arm (--backend sim
// --clock sim) run as separate processes over real UDP multicast inside a private network
// namespace; this test sends one ARM_COMMAND nudge and watches SIM_STATE: the arm's planned
// joints drive the simulated servos, the pad pushes, and the cup slides 1-3 cm, upright
// (thesis fig. 6.3-6.4). Needs root for the namespace: skipped otherwise.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "nudge/arm_command_t.hpp"
#include "nudge/arm_state_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/test/private_network.hpp"
#include "nudge/test/process.hpp"

namespace channel = nudge::bus::channel;

namespace {

const std::string kBin = NUDGE_BIN_DIR;
const std::string kUrl = nudge::test::kPrivateLcmUrl;

using nudge::test::Process;

struct Watch {
  std::optional<nudge::sim_state_t> sim;
  std::optional<nudge::arm_state_t> arm;
  void on_sim(const lcm::ReceiveBuffer*, const std::string&, const nudge::sim_state_t* m) { sim = *m; }
  void on_arm(const lcm::ReceiveBuffer*, const std::string&, const nudge::arm_state_t* m) { arm = *m; }
};

double tilt_of(const nudge::pose_t& pose) {
  const Eigen::Quaterniond q = nudge::bus::orientation_of(pose).normalized();
  return std::acos(std::clamp((q * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0));
}

}  // namespace

TEST(ArmWorld, TheArmServiceNudgesACupWithTheSimulatedPuma) {
  NUDGE_TEST_ENTER_PRIVATE_NETWORK();
  const std::string dir = testing::TempDir();
  const std::string scene = dir + "/arm_world.yaml";
  std::ofstream(scene) << "%YAML:1.0\n---\nseed: 1\n"
                       << "arm: { present: 1, joints_deg: [0, 90, -90, 0, 0, 0] }\n"
                       << "objects:\n  - { kind: cup, name: cup, position: [0.25, 0.0] }\n";
  lcm::LCM lcm(kUrl);
  ASSERT_TRUE(lcm.good());
  Watch watch;
  lcm.subscribe(channel::SIM_STATE, &Watch::on_sim, &watch);
  lcm.subscribe(channel::ARM_STATE, &Watch::on_arm, &watch);

  Process arm({kBin + "/nudge-arm", "--lcm-url", kUrl, "--backend", "sim", "--clock", "sim", "--speed-scale", "1"},
              dir + "/arm_world_arm.log");
  usleep(300000);  // the arm service listens before the world's first state
  Process world({kBin + "/nudge-world", "--lcm-url", kUrl, "--scene", scene, "--realtime-factor", "1", "--rate", "50",
                 "--duration", "60"},
                dir + "/arm_world_world.log");
  ASSERT_TRUE(arm.started() && world.started());
  using Clock = std::chrono::steady_clock;
  auto handle_until = [&](auto done, double seconds) {
    const auto end = Clock::now() + std::chrono::duration<double>(seconds);
    while (!done() && Clock::now() < end) lcm.handleTimeout(50);
    return done();
  };
  ASSERT_TRUE(handle_until([&] { return watch.sim && watch.arm; }, 30)) << "no SIM_STATE and ARM_STATE";
  // The arm drives to its home pose first (ARM_STATE's joints): let the servos get there.
  ASSERT_TRUE(handle_until([&] { return watch.sim->utime > 3000000; }, 30));
  ASSERT_EQ(watch.sim->num_objects, 1);
  const nudge::pose_t before = watch.sim->objects[0].pose;

  nudge::arm_command_t nudge{};
  nudge.utime = watch.sim->utime;
  nudge.seq = 1;
  nudge.command = nudge::arm_command_t::COMMAND_NUDGE;
  nudge.target.position[0] = 0.25;  // the cup's axis on the table, world frame
  nudge.target.orientation[0] = 1;
  nudge.direction[1] = 1;           // pushed along +y, across the cameras' view
  lcm.publish(channel::ARM_COMMAND, &nudge);
  ASSERT_TRUE(handle_until([&] { return watch.arm->command_seq == 1 && watch.arm->motion != nudge::arm_state_t::MOTION_MOVING &&
                                        watch.arm->motion != nudge::arm_state_t::MOTION_IDLE; }, 45))
      << "the nudge did not finish";
  ASSERT_EQ(watch.arm->motion + 0, nudge::arm_state_t::MOTION_DONE + 0) << watch.arm->last_error;
  const int64_t done = watch.sim->utime;
  ASSERT_TRUE(handle_until([&] { return watch.sim->utime > done + 1500000; }, 10));  // settle

  const nudge::pose_t after = watch.sim->objects[0].pose;
  const double dx = after.position[0] - before.position[0], dy = after.position[1] - before.position[1];
  std::cout << "cup moved (" << dx << ", " << dy << ") m, tilt " << tilt_of(after) * 180 / M_PI << " deg\n";
  EXPECT_GT(std::hypot(dx, dy), 0.01) << "the cup moved 1-3 cm (" << dx << ", " << dy << ")";
  EXPECT_LT(std::hypot(dx, dy), 0.03) << "the cup moved 1-3 cm (" << dx << ", " << dy << ")";
  EXPECT_GT(dy, 0.008) << "along the push";
  EXPECT_LT(tilt_of(after), 5 * M_PI / 180) << "upright";
}
