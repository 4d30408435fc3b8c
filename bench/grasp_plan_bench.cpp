// Google Benchmark: the grasp planned after the nudge (thesis sec. 7.2, "the grasping can be
// planned and performed 160 ms after the robotic nudge"; target here <= 50 ms). What the supervisor
// computes between the after stills' arrival and the GRASP command, as it does it: both cameras'
// symmetry lines in the 1280x960 stills (before and after), both motion segmentations (sec. 6.4),
// the object's top in each, its triangulation and r tan(theta) lowering, and the arm service's own
// planner on the grasp. The scene is the simulated lab's calibration (config/calibration_sim.yaml):
// a textured table, a shaded 7 x 12 cm object slid 3 cm by the nudge.
#include <benchmark/benchmark.h>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <fstream>
#include <future>
#include <string>

#include "nudge/memory.hpp"
#include "nudge/segmentation/motion.hpp"

#include "nudge/robot/command_planner.hpp"
#include "nudge/supervisor/grasp.hpp"
#include "nudge/supervisor/line_search.hpp"
#include "nudge/supervisor/report.hpp"
#include "nudge/supervisor/segment.hpp"
#include "nudge/supervisor/targets.hpp"

namespace sv = nudge::supervisor;

namespace {

const cv::Size kStill(1280, 960);
constexpr double kHeight = 0.25;  // the supervisor's tallest expected object

cv::Mat draw(const sv::SceneGeometry& scene, const Eigen::Vector3d& foot, bool left) {
  cv::Mat image(kStill, CV_8UC3);
  cv::RNG rng(7);
  rng.fill(image, cv::RNG::UNIFORM, 60, 160);
  cv::GaussianBlur(image, image, cv::Size(7, 7), 0);
  const Eigen::Vector3d across(0, 1, 0);
  for (int band = 0; band < 4; ++band) {  // darker towards the sides, like a shaded cylinder
    const double half = 0.035 * (1.0 - 0.25 * band);
    const Eigen::Vector3d up(0, 0, 0.12 - 0.01 * band);
    std::vector<cv::Point> corners;
    const std::vector<Eigen::Vector3d> outline = {foot - half * across, foot + half * across, foot + half * across + up, foot - half * across + up};
    for (const Eigen::Vector3d& c : outline) {
      const auto p = left ? scene.project_left(c, kStill) : scene.project_right(c, kStill);
      corners.emplace_back(cvRound(p->x), cvRound(p->y));
    }
    cv::fillConvexPoly(image, corners, cv::Scalar(200 - 45 * band, 60 + 30 * band, 40 + 40 * band));
  }
  return image;
}

struct Camera {
  cv::Mat before, after;
  std::optional<nudge::symmetry::Line> predicted_before, predicted_after;
};

void BM_GraspPlanAfterNudge(benchmark::State& state) {
  cv::setNumThreads(0);
  const sv::SceneGeometry scene = sv::SceneGeometry::load(NUDGE_SOURCE_DIR "/config/calibration_sim.yaml");
  const Eigen::Vector3d before(0.25, -0.02, 0), after(0.25, 0.01, 0);
  Camera cameras[2];
  for (int c = 0; c < 2; ++c) {
    const bool left = c == 0;
    cameras[c].before = draw(scene, before, left);
    cameras[c].after = draw(scene, after, left);
    cameras[c].predicted_before = left ? scene.left_axis_line(before, kHeight, kStill) : scene.right_axis_line(before, kHeight, kStill);
    cameras[c].predicted_after = left ? scene.left_axis_line(after, kHeight, kStill) : scene.right_axis_line(after, kHeight, kStill);
  }
  // As the shell sets the supervisor up: both segmentations for the grasp without fig. 6.7's
  // stages (the right camera's are drawn after the grasp is commanded).
  const sv::SegmentFunction segment = sv::motion_segmentation({}, false);
  const sv::ArmSetup arm;
  // The before stills' lines are found before the nudge (Supervisor: when the stills arrive).
  sv::LineSearchParams search;
  search.crop_to_prediction = state.range(1) != 0;
  std::optional<nudge::symmetry::Line> before_lines[2];
  for (int c = 0; c < 2; ++c) before_lines[c] = sv::find_line_near(cameras[c].before, *cameras[c].predicted_before, search);
  const sv::SegmentFunction segment_left = sv::motion_segmentation({}, false);  // the left's own, as the shell sets it
  const bool parallel = state.range(0) != 0;
  double grasp_height = 0;
  for (auto _ : state) {
    std::optional<cv::Point2d> top[2];
    std::optional<Eigen::Vector3d> mask_foot;  // the supervisor's check of the settled axes' rest
    auto camera_top = [&](int c) {
      const Camera& cam = cameras[c];
      auto line_before = before_lines[c];
      // As the supervisor: first at the before line's lean (find_moved_line).
      auto line_after = sv::find_moved_line(cam.after, *cam.predicted_after, *cam.predicted_before, line_before, search);
      if (!line_before) line_before = cam.predicted_before;
      if (!line_after) line_after = cam.predicted_after;
      const sv::Segmentation s = (c == 0 ? segment_left : segment)(cam.before, cam.after, *line_before, *line_after);
      // The right mask's checks (Supervisor::mask_shape_problem): its mirror image about the line.
      if (c == 1 && nudge::segmentation::mirror_agreement(s.mask, *line_after) < 0.5) return;
      const auto reading = sv::read_mask_on_line(s.mask, *line_after);
      if (!reading) return;
      top[c] = reading->top;
      if (c == 1) mask_foot = sv::foot_from_mask(scene, *reading);
    };
    // As the supervisor does it: the left camera on a second thread (range 1) or after the right (0).
    std::future<void> left = std::async(parallel ? std::launch::async : std::launch::deferred, camera_top, 0);
    camera_top(1);
    left.get();
    if (!top[0] || !top[1] || !mask_foot) {
      state.SkipWithError("no object top or foot");
      return;
    }
    const sv::GraspTarget g = sv::grasp_target(scene, *top[0], *top[1], kStill, after);
    nudge::robot::Command command;
    command.kind = nudge::robot::CommandKind::Grasp;
    command.target_position = g.foot;
    command.height = g.grasp_height_m;
    const nudge::robot::MotionPlan plan = nudge::robot::plan_command(arm.planner(), command, arm.home());
    if (!g.ok() || !plan.ok()) {
      state.SkipWithError((g.reason + plan.reason).c_str());
      return;
    }
    grasp_height = g.grasp_height_m;
  }
  state.counters["grasp_height_mm"] = grasp_height * 1e3;  // a wrong plan shows here
}
// Args: the left camera on a second thread (1) or after the right (0); the line searches in the band
// about the prediction (1, as the supervisor does) or in the whole still (0).
BENCHMARK(BM_GraspPlanAfterNudge)->Args({0, 1})->Args({1, 1})->Args({1, 0})->Unit(benchmark::kMillisecond)->MinTime(2.0)->UseRealTime();

// Its parts: one line search in a still, one motion segmentation.
void BM_LineSearchInStill(benchmark::State& state) {
  cv::setNumThreads(0);
  const sv::SceneGeometry scene = sv::SceneGeometry::load(NUDGE_SOURCE_DIR "/config/calibration_sim.yaml");
  const Eigen::Vector3d foot(0.25, 0.01, 0);
  const cv::Mat still = draw(scene, foot, false);
  const auto predicted = scene.right_axis_line(foot, kHeight, kStill);
  sv::LineSearchParams params;
  params.crop_to_prediction = state.range(0) != 0;
  for (auto _ : state) benchmark::DoNotOptimize(sv::find_line_near(still, *predicted, params));
  state.counters["searched_share"] =
      params.crop_to_prediction ? static_cast<double>(sv::search_region(still.size(), *predicted, params).area()) / still.total() : 1.0;
}
// Arg: the band about the prediction searched (1, as the supervisor does) or the whole still (0).
BENCHMARK(BM_LineSearchInStill)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

void BM_MotionSegmentationOfStills(benchmark::State& state) {
  cv::setNumThreads(0);
  const sv::SceneGeometry scene = sv::SceneGeometry::load(NUDGE_SOURCE_DIR "/config/calibration_sim.yaml");
  const Eigen::Vector3d before(0.25, -0.02, 0), after(0.25, 0.01, 0);
  const cv::Mat a = draw(scene, before, false), b = draw(scene, after, false);
  const auto la = scene.right_axis_line(before, kHeight, kStill), lb = scene.right_axis_line(after, kHeight, kStill);
  const sv::SegmentFunction segment = sv::motion_segmentation({}, state.range(0) != 0);
  for (auto _ : state) benchmark::DoNotOptimize(segment(a, b, *la, *lb));
}
// Arg: fig. 6.7's stages kept (1, the right camera's) or not (0, the left camera's).
BENCHMARK(BM_MotionSegmentationOfStills)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond);

void BM_GraspCheckByTheArmsPlanner(benchmark::State& state) {
  const sv::ArmSetup arm;
  nudge::robot::Command command;
  command.kind = nudge::robot::CommandKind::Grasp;
  command.target_position = Eigen::Vector3d(0.25, 0.01, 0);
  command.height = 0.09;
  for (auto _ : state) benchmark::DoNotOptimize(nudge::robot::plan_command(arm.planner(), command, arm.home()));
}
BENCHMARK(BM_GraspCheckByTheArmsPlanner)->Unit(benchmark::kMillisecond);

}  // namespace

// The after still's mask read once on the critical path: the object's top (the grasp height)
// and its foot (the check of the settled axes' rest), from one labelling of its largest blob.
void BM_MaskTopAndFoot(benchmark::State& state) {
  const sv::SceneGeometry scene = sv::SceneGeometry::load(NUDGE_SOURCE_DIR "/config/calibration_sim.yaml");
  const Eigen::Vector3d after(0.28, -0.02, 0);
  // The object's outline (draw()'s outer band) filled: the segmentation's mask of it.
  cv::Mat mask = cv::Mat::zeros(kStill, CV_8U);
  const Eigen::Vector3d across(0, 0.035, 0), up(0, 0, 0.12);
  std::vector<cv::Point> corners;
  for (const Eigen::Vector3d& c : {Eigen::Vector3d(after - across), Eigen::Vector3d(after + across), Eigen::Vector3d(after + across + up),
                                   Eigen::Vector3d(after - across + up)}) {
    const auto p = scene.project_right(c, kStill);
    corners.emplace_back(cvRound(p->x), cvRound(p->y));
  }
  cv::fillConvexPoly(mask, corners, cv::Scalar(255));
  const auto line = scene.right_axis_line(after, kHeight, kStill);
  for (auto _ : state) {
    const auto reading = sv::read_mask_on_line(mask, *line);  // once, as the supervisor reads it
    benchmark::DoNotOptimize(sv::foot_from_mask(scene, *reading));
  }
}
BENCHMARK(BM_MaskTopAndFoot)->Unit(benchmark::kMillisecond);

// A drawn object pushed 3 cm across the right camera's view: its after still, its line there and
// the motion segmentation's mask of it (the mask checks' input).
struct DrawnPush {
  cv::Mat after, mask;
  nudge::symmetry::Line after_line;
};

DrawnPush drawn_push() {
  const sv::SceneGeometry scene = sv::SceneGeometry::load(NUDGE_SOURCE_DIR "/config/calibration_sim.yaml");
  const Eigen::Vector3d before(0.25, -0.02, 0), after(0.25, 0.01, 0);
  const cv::Mat a = draw(scene, before, false), b = draw(scene, after, false);
  const auto la = scene.right_axis_line(before, kHeight, kStill), lb = scene.right_axis_line(after, kHeight, kStill);
  return {b, sv::motion_segmentation({}, false)(a, b, *la, *lb).mask, *lb};
}

// The mask's mirror check of the right camera's segmentation (Supervisor::mask_shape_problem).
void BM_MaskMirrorAgreement(benchmark::State& state) {
  const DrawnPush push = drawn_push();
  double agreement = 0;
  for (auto _ : state) benchmark::DoNotOptimize(agreement = nudge::segmentation::mirror_agreement(push.mask, push.after_line));
  state.counters["agreement"] = agreement;
}
BENCHMARK(BM_MaskMirrorAgreement)->Unit(benchmark::kMillisecond);

// The mask's side-edge check (Supervisor::mask_shape_problem): Canny on the grey still and each
// colour channel around the mask's box, then each row's two sides looked up.
void BM_MaskSideEdgeSupport(benchmark::State& state) {
  const DrawnPush push = drawn_push();
  double support = 0;
  for (auto _ : state) benchmark::DoNotOptimize(support = nudge::segmentation::side_edge_support(push.mask, push.after));
  state.counters["support"] = support;
  state.counters["mask_px"] = cv::countNonZero(push.mask);
}
BENCHMARK(BM_MaskSideEdgeSupport)->Unit(benchmark::kMillisecond);

// The right camera's part of the plan on a recorded attempt's stills (an attempt folder of a run:
// before.png, after.png and attempt.json's line_before and line_after): the motion segmentation
// without stages, the mask's mirror check, its top and foot and its side-edge check, as the supervisor runs them.
void BM_RecordedAttempt(benchmark::State& state, const std::string& folder) {
  cv::setNumThreads(0);
  std::ifstream in(folder + "/attempt.json");
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const cv::Mat before = cv::imread(folder + "/before.png"), after = cv::imread(folder + "/after.png");
  const auto line_before = sv::recorded_line(json, "line_before"), line_after = sv::recorded_line(json, "line_after");
  if (before.empty() || after.empty() || !line_before || !line_after) {
    state.SkipWithError(("not an attempt folder with stills and lines: " + folder).c_str());
    return;
  }
  const sv::SegmentFunction segment = sv::motion_segmentation({}, false);
  const int part = static_cast<int>(state.range(0));
  const cv::Mat mask = segment(before, after, *line_before, *line_after).mask;
  const double mask_pixels = cv::countNonZero(mask);
  for (auto _ : state) {
    if (part == 0) benchmark::DoNotOptimize(segment(before, after, *line_before, *line_after));
    if (part == 1) benchmark::DoNotOptimize(nudge::segmentation::mirror_agreement(mask, *line_after));
    if (part == 2) benchmark::DoNotOptimize(sv::read_mask_on_line(mask, *line_after));
    if (part == 3) benchmark::DoNotOptimize(nudge::segmentation::side_edge_support(mask, after));
  }
  state.counters["mask_px"] = mask_pixels;
}

// As the services run (bus::guarded_main keeps freed images in the heap), unless --fresh-pages
// asks for glibc's defaults: every image a fresh map, a page fault per page (nudge/memory.hpp).
// --attempt FOLDER (repeatable) adds BM_RecordedAttempt on that attempt's stills: /0 the
// segmentation, /1 the mirror check, /2 the mask's top and foot, /3 the side-edge check.
int main(int argc, char** argv) {
  bool fresh_pages = false;
  std::vector<std::string> attempts;
  int kept = 1;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--fresh-pages") fresh_pages = true;
    else if (arg == "--attempt" && i + 1 < argc) attempts.push_back(argv[++i]);
    else argv[kept++] = argv[i];
  }
  argc = kept;
  if (!fresh_pages) nudge::keep_large_buffers_for_reuse();
  for (const std::string& folder : attempts)
    benchmark::RegisterBenchmark(("BM_RecordedAttempt:" + folder).c_str(), BM_RecordedAttempt, folder)
        ->Arg(0)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::AddCustomContext("memory", fresh_pages ? "glibc defaults (--fresh-pages)" : "freed images kept for reuse");
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
