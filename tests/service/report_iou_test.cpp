// nudge-report --scene: the IoU of a run's segmentation against the simulator's truth, from a log
// laid out as the demo's (SIM_STATE, the supervisor's SEGMENT state, SEGMENTATION at the end of
// the attempt, after the object was moved again by learning).
#include <gtest/gtest.h>
#include <unistd.h>

#include <opencv2/imgproc.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>

#include "nudge/bus/channels.hpp"
#include "nudge/bus/image.hpp"
#include "nudge/bus/pose_convert.hpp"
#include "nudge/segmentation_t.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "nudge/test/lcm_log.hpp"
#include "nudge/test/process.hpp"
#include "nudge/test/run_service.hpp"

using namespace nudge;
namespace fs = std::filesystem;

namespace {

const std::string kScene = std::string(NUDGE_SOURCE_DIR) + "/common/sim/scenes/three_objects.yaml";

sim_state_t state_of(const sim::World& world, int64_t utime) {
  const sim::PoseSnapshot poses = sim::snapshot_poses(world, 0);
  sim_state_t msg{};
  msg.utime = utime;
  msg.gripper = -1;
  msg.num_objects = static_cast<int32_t>(poses.objects.size());
  for (const sim::ObjectPose& p : poses.objects) {
    object_state_t o{};
    o.name = p.name;
    o.pose = bus::to_message(p.position, p.orientation);
    msg.objects.push_back(o);
  }
  msg.pusher = bus::to_message(poses.pusher_position, Eigen::Quaterniond::Identity());
  return msg;
}

supervisor_state_t supervisor_state(int64_t utime, const std::string& name, int attempt) {
  supervisor_state_t msg{};
  msg.utime = utime;
  msg.run_id = "iou";
  msg.state_name = name;
  msg.attempt = attempt;
  return msg;
}

}  // namespace

TEST(ReportIoU, ScoresTheMaskAgainstTheWorldWhenSegmentationBeganPerObject) {
  sim::Scene scene = sim::load_scene(kScene);
  scene.render.noise_sigma = 0;
  sim::World world(scene);
  const cv::Mat labels = world.render_snapshot_mask(1);
  // The mask: object 1's true mask, eroded, so that its IoU is known exactly.
  cv::Mat object = labels == 2, mask;
  cv::erode(object, mask, cv::getStructuringElement(cv::MORPH_RECT, {9, 9}));
  const double expected_iou = static_cast<double>(cv::countNonZero(mask)) / cv::countNonZero(object);
  ASSERT_GT(expected_iou, 0.5);
  ASSERT_LT(expected_iou, 0.98);

  const fs::path dir = fs::path(testing::TempDir()) / ("report_iou_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "summary.json") << R"({"run_id": "iou", "attempts": 1, "segmented": 1,
    "attempt_list": [{"attempt": 1, "outcome": "segmented", "reason": "segmented"}]})";
  {
    test::LogWriter log((dir / "run.lcmlog").string());
    log.write(1000000, bus::channel::SIM_STATE, state_of(world, 1000000));
    log.write(1050000, bus::channel::SUPERVISOR_STATE, supervisor_state(1050000, "SEGMENT", 1));
    // Learning then moves the object away before the attempt ends and SEGMENTATION is sent.
    const sim::PoseSnapshot before = sim::snapshot_poses(world, 0);
    world.set_object_pose(1, before.objects[1].position + Eigen::Vector3d(0.08, 0.05, 0), before.objects[1].orientation);
    log.write(2000000, bus::channel::SIM_STATE, state_of(world, 2000000));
    segmentation_t seg{};
    seg.utime = 2500000;
    seg.run_id = "iou";
    seg.attempt = 1;
    seg.mask_pixels = cv::countNonZero(mask);
    seg.mask = bus::to_message(mask, image_t::FORMAT_PNG, seg.utime, 1, "right");
    log.write(2500000, bus::channel::SEGMENTATION, seg);
  }
  const std::string cmd = std::string(NUDGE_BIN_DIR) + "/nudge-report " + dir.string() + " --log " +
                          (dir / "run.lcmlog").string() + " --scene " + kScene;
  const test::CommandOutput result = test::run_capturing(cmd);
  ASSERT_EQ(result.exit_code, 0) << cmd << "\n" << result.err;
  const std::string html = test::read_file((dir / "report.html").string());
  char iou[16];
  std::snprintf(iou, sizeof iou, "%.3f", expected_iou);
  const std::string name = scene.objects[1].name;
  EXPECT_NE(html.find("IoU (simulation) " + std::string(iou) + " with " + name + " (object 1)"), std::string::npos)
      << "expected " << iou << "\n" << html;
  EXPECT_NE(html.find("<tr><td>" + name + " (object 1)</td><td>1 (" + iou + ")</td>"), std::string::npos);

  // A scene the run did not use (other still size or objects) is refused naming the log, not scored.
  const test::CommandOutput bad = test::run_capturing(std::string(NUDGE_BIN_DIR) + "/nudge-report " + dir.string() +
                                                      " --log " + (dir / "run.lcmlog").string() + " --scene /nonexistent.yaml");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("/nonexistent.yaml"), std::string::npos) << bad.err;
  fs::remove_all(dir);
}
