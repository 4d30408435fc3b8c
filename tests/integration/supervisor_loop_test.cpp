// Integration: the whole autonomous segmentation loop (thesis ch. 6) over UDP multicast in a
// private network namespace: world (MuJoCo) -> camera (sim, stills) -> symmetry -> triangulation,
// the arm service on the simulated clock, and the supervisor, each its own process. A cup stands on
// the table; the supervisor must find it, nudge it and cut it out of the right camera's stills,
// then end the run by itself. Its run log, fed back to a second supervisor as fast as it can read,
// must give the same states and arm commands (the regression check of replays).
// Needs root for the namespace: skipped otherwise.
#include <gtest/gtest.h>
#include <lcm/lcm-cpp.hpp>
#include <unistd.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "nudge/arm_command_t.hpp"
#include "nudge/bus/channels.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor/scene.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/test/loop_services.hpp"

using nudge::test::loop_supervisor_command;
using nudge::test::LoopServices;
using nudge::test::LoopSetup;
using nudge::test::replay_supervisor_command;
using nudge::test::Process;
using nudge::test::read_file;
namespace channel = nudge::bus::channel;

namespace {

const std::string kSource = NUDGE_SOURCE_DIR;
const std::string kCalibration = kSource + "/config/calibration_sim.yaml";

int json_int(const std::string& json, const std::string& key) {
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\":(-?[0-9]+)"))) return -1;
  return std::stoi(m[1]);
}

// What the supervisor decided, as a replay must re-derive it: its state transitions (the 1 Hz
// repeats dropped) and its arm commands.
struct Decisions {
  std::vector<std::string> states, commands;
  std::optional<nudge::sim_state_t> last_sim;
};

Decisions read_decisions(const std::string& log_path) {
  Decisions d;
  lcm::LogFile log(log_path, "r");
  EXPECT_TRUE(log.good()) << log_path;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel == channel::SUPERVISOR_STATE) {
      nudge::supervisor_state_t m;
      if (m.decode(e->data, 0, e->datalen) < 0) continue;
      const std::string text = m.state_name + " #" + std::to_string(m.attempt) + ": " + m.reason;
      if (d.states.empty() || d.states.back() != text) d.states.push_back(text);
    } else if (e->channel == channel::ARM_COMMAND) {
      nudge::arm_command_t m;
      if (m.decode(e->data, 0, e->datalen) < 0) continue;
      char text[160];
      std::snprintf(text, sizeof text, "seq %lld command %d at (%.4f, %.4f) along (%.3f, %.3f)",
                    static_cast<long long>(m.seq), m.command, m.target.position[0], m.target.position[1],
                    m.direction[0], m.direction[1]);
      d.commands.push_back(text);
    } else if (e->channel == channel::SIM_STATE) {
      nudge::sim_state_t m;
      if (m.decode(e->data, 0, e->datalen) >= 0) d.last_sim = m;
    }
  }
  return d;
}

}  // namespace

TEST(SupervisorLoop, FindsNudgesAndSegmentsACupThenReplaysItsRunIdentically) {
  NUDGE_TEST_ENTER_PRIVATE_NETWORK();
  // Per process: two checkouts testing at once on one machine must not share it.
  const std::string dir = ::testing::TempDir() + "/supervisor_loop_" + std::to_string(getpid());
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string scene = kSource + "/common/sim/scenes/single_cup.yaml";

  LoopSetup setup;
  setup.dir = dir;
  setup.scene = scene;
  setup.calibration = kCalibration;
  LoopServices services(setup);
  ASSERT_EQ(services.start_all(), std::vector<std::string>{}) << "services that did not start";
  Process supervisor(loop_supervisor_command(setup, "loop"), dir + "/supervisor.log");
  ASSERT_TRUE(supervisor.started());
  const int code = supervisor.wait_exit(240);
  ASSERT_EQ(code, 0) << "the supervisor did not end its run by itself: " << read_file(dir + "/supervisor.log");

  const std::string summary = read_file(dir + "/loop/summary.json");
  EXPECT_EQ(json_int(summary, "segmented"), 1) << summary;
  EXPECT_GE(json_int(summary, "attempts"), 1) << summary;  // a phantom may cost an attempt more
  const cv::Mat mask = cv::imread(dir + "/loop/attempt_01/mask.png", cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(mask.empty()) << summary;
  EXPECT_EQ(mask.size(), cv::Size(1280, 960));

  // The mask is the cup where the simulator put it after the nudge: the middle of its axis is in
  // the mask, and the mask is about a cup's size (7-8 cm wide, 10 cm tall at ~0.65 m: ~15000 px).
  const std::string log = dir + "/loop/loop.lcmlog";
  const Decisions live = read_decisions(log);
  ASSERT_TRUE(live.last_sim);
  ASSERT_EQ(live.last_sim->num_objects, 1);
  const auto geometry = nudge::supervisor::SceneGeometry::load(kCalibration);
  const double* p = live.last_sim->objects[0].pose.position;
  const auto centre = geometry.project_right(Eigen::Vector3d(p[0], p[1], 0.05), mask.size());
  ASSERT_TRUE(centre);
  EXPECT_GT(mask.at<uint8_t>(cvRound(centre->y), cvRound(centre->x)), 0) << "the cup's axis is not in the mask";
  const int area = cv::countNonZero(mask);
  EXPECT_GT(area, 5000);
  EXPECT_LT(area, 60000);

  // Replay: the same decisions from the log alone.
  Process replay(replay_supervisor_command(setup, log, dir + "/replay_out.lcmlog", "replay"), dir + "/replay.log");
  ASSERT_EQ(replay.wait_exit(60), 0) << read_file(dir + "/replay.log");
  const Decisions replayed = read_decisions(dir + "/replay_out.lcmlog");
  EXPECT_EQ(replayed.states, live.states) << read_file(dir + "/replay.log");
  EXPECT_EQ(replayed.commands, live.commands);
  EXPECT_GE(live.commands.size(), 1u);
  EXPECT_EQ(json_int(read_file(dir + "/replay/summary.json"), "segmented"), 1);
  // The run's log is most of a gigabyte (every camera frame): kept only for a look at a failure.
  if (!HasFailure()) std::filesystem::remove_all(dir);
}
