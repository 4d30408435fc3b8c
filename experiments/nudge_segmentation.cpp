// Thesis sec. 6.5 in simulation: autonomous segmentation by a robotic nudge, scored against the
// simulator's truth. experiments/nudge_segmentation.sh runs the whole loop (every service its own
// process) on each evaluation scene of experiments/scenes/nudge_segmentation/ (fixed before the
// first run, never re-staged); this program reads each run's LCM log and files and writes
// docs/results/nudge_segmentation.{json,md} with a gallery.
//
// Per segmentation: the SIM_STATE at the after still is re-rendered at 1280x960 with the scene's
// own World (label mask: the simulator's truth, a mug's handle included); the object the mask
// overlaps most is the one segmented; IoU with it, and the mask's pixels on the end effector (pad
// or gripper: the pixels that change when it is hidden) are counted. A segmentation of an object
// lying fallen (over 45 deg) does not count as segmented; every state is read for the objects that
// fell, when, and where the pad was as each began to lean.
//   nudge-exp-nudge-segmentation RUNS_DIR SCENE_DIR [RUN...] [--development RUNS_DIR SCENE_DIR]
//                                [--name STEM] [--workspace FILE] [--development-set]
// (default: every scene in SCENE_DIR). Objects a scene stages outside the workspace ring (FILE's,
// default the code's) are counted apart: the loop's candidates are within the ring. The first set gives the headline keys (the held-out scenes); the
// development set goes under its own key "development".
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "nudge/bus/image.hpp"
#include "nudge/bus/sim_convert.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/robot/workspace.hpp"
#include "nudge/segmentation/motion.hpp"
#include "nudge/segmentation_t.hpp"
#include "nudge/sim/mask_score.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor/report.hpp"
#include "nudge/supervisor_state_t.hpp"
#include "report.hpp"

namespace fs = std::filesystem;
namespace ex = nudge::experiments;
using namespace nudge;

namespace {

constexpr int kRight = 1;
// An object whose axis leans more than this in the simulator has fallen over (upright objects lean
// a degree or two at most; one lying on its side, 90).
constexpr double kFallenDeg = 45;
constexpr double kTippingDeg = 5;  // a lean past this that goes on to kFallenDeg: when the fall began

// "object 2 (the pad 18 mm from its foot, 122 mm up, as it began to lean) in attempt 3 (NUDGE, its
// target)": the object fell after `before` (the last state that showed it standing), having begun
// to lean at `tipping`, while the supervisor was as `supervisor` last said. The target is the
// object when the attempt's target lay within 6 cm of where the object stood.
std::string fall_description(int object, const sim_state_t& before, const sim_state_t& tipping,
                             const std::optional<supervisor_state_t>& supervisor) {
  std::string text = "object " + std::to_string(object);
  // Where the pad was when it began to lean: beside it, the pad pushed it; far off, the arm's links.
  if (object < tipping.num_objects) {
    const auto& at = tipping.objects[static_cast<size_t>(object)].pose.position;
    const auto& pad = tipping.pusher.position;
    char where[96];
    std::snprintf(where, sizeof where, " (the pad %.0f mm from its foot, %.0f mm up, as it began to lean)",
                  1000 * std::hypot(pad[0] - at[0], pad[1] - at[1]), 1000 * pad[2]);
    text += where;
  }
  if (!supervisor) return text + " before the supervisor's first state";
  text += " in attempt " + std::to_string(supervisor->attempt) + " (" + supervisor->state_name;
  if (object < before.num_objects && supervisor->attempt > 0) {
    const auto& stood = before.objects[static_cast<size_t>(object)].pose.position;
    const double apart = std::hypot(stood[0] - supervisor->target[0], stood[1] - supervisor->target[1]);
    text += apart < 0.06 ? ", its target" : ", not its target";
  }
  return text + ")";
}

// Each object's lean in a recorded state: the angle between its body's z axis and the world's.
std::vector<double> object_tilts_deg(const sim_state_t& state) {
  std::vector<double> tilts;
  for (const sim::ObjectPose& pose : bus::poses_of(state).objects) {
    const double cosine = std::clamp((pose.orientation * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0);
    tilts.push_back(std::acos(cosine) * 180 / M_PI);
  }
  return tilts;
}

struct Segmented {
  int attempt = 0;
  int object = -1;           // scene index of the object the mask covers most; -1: none
  double iou = 0;
  int effector_pixels = 0;
  int tool_changed_pixels = 0;  // effector pixels and the tool's shadow
  int mask_pixels = 0;
  double object_tilt_deg = 0;  // the segmented object's lean in the simulator at the after still
  cv::Mat gallery;           // before | after | mask over after
  std::string reason;        // a refused mask's: why the supervisor refused it (attempt.json)
};

struct Run {
  std::string name;
  int objects_present = 0;
  int attempts = 0, no_motion = 0, tipped = 0, other_failures = 0;
  // Segmentations whose object lay fallen (leaning beyond kFallenDeg in the simulator) when the
  // after still was taken: the supervisor should have called the attempt tipped, not segmented.
  int segmented_fallen = 0;
  std::set<int> objects_fallen;  // scene indices lying fallen at the run's last recorded state
  // When each of those fell (fall_description), from the supervisor's state published last before
  // the first recorded state that shows it fallen.
  std::vector<std::string> falls;
  double wall_s = 0;
  std::string end_reason;
  std::vector<Segmented> segmented;
  // Masks the supervisor cut but refused (the attempt ended "segmentation failed" with its
  // mask.png written), scored against the same truth: whether the refusal checks
  // (Supervisor::mask_shape_problem) turn away good masks as well as bad ones.
  std::vector<Segmented> refused;
  std::set<int> objects_found;  // scene indices segmented with IoU >= 0.5, standing
  // Scene indices of the objects the scene stages outside the arm's workspace ring (the object's
  // axis nearer the base than ring_inner or farther than ring_outer): the candidates the
  // triangulation gives are within the ring, so the loop cannot be expected to find these.
  std::set<int> objects_beyond_reach;
  bool success() const { return !objects_found.empty(); }
};

std::string read_text(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

int json_int(const std::string& json, const std::string& key) {
  std::smatch m;
  return std::regex_search(json, m, std::regex("\"" + key + "\":(-?[0-9]+)")) ? std::stoi(m[1]) : 0;
}

std::string json_string(const std::string& json, const std::string& key) {
  std::smatch m;
  return std::regex_search(json, m, std::regex("\"" + key + "\":\"([^\"]*)\"")) ? std::string(m[1]) : "";
}

// The truth of one recorded state in the right still: label mask, the end effector's own pixels,
// and every pixel the tool changes (itself and its shadow: the count reported before 2026-11-25).
struct Truth {
  cv::Mat labels, effector, tool_changed;
};

Truth render_truth(sim::World& world, const sim_state_t& state) {
  sim::apply_poses(world, bus::poses_of(state));
  Truth truth;
  truth.labels = world.render_snapshot_mask(kRight);
  world.pusher_visible = true;
  const cv::Mat with = world.render_snapshot(kRight);
  world.pusher_visible = false;
  const cv::Mat without = world.render_snapshot(kRight);
  world.pusher_visible = true;
  cv::Mat change;
  cv::absdiff(with, without, change);
  cv::cvtColor(change, change, cv::COLOR_BGR2GRAY);
  cv::threshold(change, truth.tool_changed, 10, 255, cv::THRESH_BINARY);
  truth.effector = world.render_snapshot_tool_mask(kRight);
  return truth;
}

Segmented score(const cv::Mat& mask, const Truth& truth, int objects) {
  Segmented s;
  const sim::MaskScore m = sim::score_mask(mask, truth.labels, objects);
  s.mask_pixels = m.mask_pixels;
  s.object = m.object;
  s.iou = m.iou;
  s.effector_pixels = cv::countNonZero(truth.effector & mask);
  s.tool_changed_pixels = cv::countNonZero(truth.tool_changed & mask);
  return s;
}

// An attempt's still, or an empty image when the attempt ended before taking it (no warning:
// attempts that ended early are normal).
cv::Mat still_of(const fs::path& attempt_dir, const char* name) {
  const fs::path path = attempt_dir / name;
  return fs::exists(path) ? cv::imread(path.string()) : cv::Mat();
}

cv::Mat gallery_row(const fs::path& attempt_dir, const cv::Mat& mask) {
  cv::Mat before = still_of(attempt_dir, "before.png"), after = still_of(attempt_dir, "after.png");
  if (before.empty() || after.empty()) return {};
  cv::Mat overlay = after.clone();
  overlay.setTo(cv::Scalar(0, 200, 0), mask);
  cv::addWeighted(after, 0.5, overlay, 0.5, 0, overlay);
  std::vector<cv::Mat> tiles = {before, after, overlay};
  for (cv::Mat& t : tiles) cv::resize(t, t, {320, 240}, 0, 0, cv::INTER_AREA);
  cv::Mat row;
  cv::hconcat(tiles, row);
  return row;
}

// The objects of `scene` whose axis stands outside the workspace ring (the world frame's origin is
// on the arm base's axis: docs/robot.md).
std::set<int> objects_beyond_reach(const sim::Scene& scene, const robot::Workspace& workspace) {
  std::set<int> beyond;
  for (size_t i = 0; i < scene.objects.size(); ++i) {
    const double radius = scene.objects[i].position.norm();
    if (radius < workspace.ring_inner || radius > workspace.ring_outer) beyond.insert(static_cast<int>(i));
  }
  return beyond;
}

// "object: IoU" of each segmentation, comma-separated ("–" for none): a cell of the runs' table.
std::string objects_and_ious(const std::vector<Segmented>& masks) {
  std::string cell;
  for (const Segmented& s : masks) {
    char text[48];
    std::snprintf(text, sizeof text, "%s%d: %.3f", cell.empty() ? "" : ", ", s.object, s.iou);
    cell += text;
  }
  return cell.empty() ? "–" : cell;
}

// Scores every mask an attempt cut but did not publish (refused by the supervisor's checks) against
// the truth at the state recorded when that attempt began to segment.
void score_refused_masks(Run& run, const fs::path& run_dir, sim::World& world,
                         const std::map<int, sim_state_t>& state_at_segment) {
  for (const auto& [attempt, state] : state_at_segment) {
    const bool published = std::any_of(run.segmented.begin(), run.segmented.end(),
                                        [&](const Segmented& s) { return s.attempt == attempt; });
    char folder[32];
    std::snprintf(folder, sizeof folder, "attempt_%02d", attempt);
    const fs::path mask_file = run_dir / folder / "mask.png";
    if (published || !fs::exists(mask_file)) continue;
    const cv::Mat mask = cv::imread(mask_file.string(), cv::IMREAD_GRAYSCALE);
    if (mask.empty() || cv::countNonZero(mask) == 0) continue;  // an empty segmentation: nothing to score
    Segmented s = score(mask, render_truth(world, state), run.objects_present);
    s.attempt = attempt;
    s.reason = json_string(read_text(run_dir / folder / "attempt.json"), "reason");
    run.refused.push_back(std::move(s));
  }
}

Run evaluate(const std::string& name, const fs::path& run_dir, const fs::path& scene_file, const robot::Workspace& workspace) {
  Run run;
  run.name = name;
  const std::string summary = read_text(run_dir / "summary.json");
  run.attempts = json_int(summary, "attempts");
  run.end_reason = json_string(summary, "end_reason");
  std::smatch m;
  if (std::regex_search(summary, m, std::regex("\"no motion\":([0-9]+)"))) run.no_motion = std::stoi(m[1]);
  if (std::regex_search(summary, m, std::regex("\"tipped or lost\":([0-9]+)"))) run.tipped = std::stoi(m[1]);
  const std::string wall = read_text(run_dir / "wall_seconds.txt");
  run.wall_s = wall.empty() ? 0 : std::stod(wall);

  sim::Scene scene = sim::load_scene(scene_file.string());
  scene.render.noise_sigma = 0;
  run.objects_present = static_cast<int>(scene.objects.size());
  run.objects_beyond_reach = objects_beyond_reach(scene, workspace);
  sim::World world(scene);
  lcm::LogFile log((run_dir / (run_dir.filename().string() + ".lcmlog")).string(), "r");
  if (!log.good()) throw std::runtime_error(run_dir.string() + ": no run log");
  std::optional<sim_state_t> last_state;
  std::optional<supervisor_state_t> supervisor;
  std::map<int, std::string> fell;  // object -> when it fell
  std::map<int, sim_state_t> tipping;  // object -> the first state of its latest lean past kTippingDeg
  std::map<int, sim_state_t> state_at_segment;  // attempt -> the last state when it began to segment
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel == "SIM_STATE") {
      sim_state_t state;
      if (state.decode(e->data, 0, e->datalen) < 0) continue;
      const std::vector<double> tilts = object_tilts_deg(state);
      for (size_t i = 0; i < tilts.size(); ++i) {
        const int object = static_cast<int>(i);
        if (tilts[i] <= kTippingDeg) tipping.erase(object);
        else if (!tipping.count(object)) tipping[object] = state;
        if (tilts[i] > kFallenDeg && !fell.count(object) && last_state)
          fell[object] = fall_description(object, *last_state, tipping.at(object), supervisor);
      }
      last_state = state;
    } else if (e->channel == "SUPERVISOR_STATE") {
      supervisor_state_t state;
      if (state.decode(e->data, 0, e->datalen) >= 0) supervisor = state;
      // The after still is taken before SEGMENT: the scene as it was then, for a refused mask.
      if (supervisor && supervisor->state == supervisor_state_t::STATE_SEGMENT && last_state)
        state_at_segment.emplace(supervisor->attempt, *last_state);
    } else if (e->channel == "SEGMENTATION" && last_state) {
      segmentation_t seg;
      if (seg.decode(e->data, 0, e->datalen) < 0) continue;
      cv::Mat mask = bus::to_mat(seg.mask);
      if (mask.channels() > 1) cv::cvtColor(mask, mask, cv::COLOR_BGR2GRAY);
      const Truth truth = render_truth(world, *last_state);
      Segmented s = score(mask, truth, run.objects_present);
      s.attempt = seg.attempt;
      const std::vector<double> tilts = object_tilts_deg(*last_state);
      if (s.object >= 0 && s.object < static_cast<int>(tilts.size())) s.object_tilt_deg = tilts[s.object];
      run.segmented_fallen += s.object_tilt_deg > kFallenDeg;
      char folder[32];
      std::snprintf(folder, sizeof folder, "attempt_%02d", seg.attempt);
      s.gallery = gallery_row(run_dir / folder, mask);
      if (s.iou >= 0.5 && s.object_tilt_deg <= kFallenDeg) run.objects_found.insert(s.object);  // a fallen one: tipped
      run.segmented.push_back(std::move(s));
    }
  }
  if (last_state) {
    const std::vector<double> tilts = object_tilts_deg(*last_state);
    for (size_t i = 0; i < tilts.size(); ++i)
      if (tilts[i] > kFallenDeg) {
        run.objects_fallen.insert(static_cast<int>(i));
        if (fell.count(static_cast<int>(i))) run.falls.push_back(fell[static_cast<int>(i)]);
      }
  }
  run.other_failures = run.attempts - static_cast<int>(run.segmented.size()) - run.no_motion - run.tipped;
  score_refused_masks(run, run_dir, world, state_at_segment);
  return run;
}

// Motion segmentation alone on the runs' stills, single-threaded: the median CPU time per 1280x960
// pair (the thread's CPU time: wall times on a shared host also count other processes' turns).
double time_motion_segmentation(const std::vector<fs::path>& attempt_dirs) {
  cv::setNumThreads(0);
  segmentation::MotionSegmenter segmenter;
  std::vector<double> ms;
  for (const fs::path& dir : attempt_dirs) {
    const std::string json = read_text(dir / "attempt.json");
    const cv::Mat before = still_of(dir, "before.png"), after = still_of(dir, "after.png");
    const auto lb = supervisor::recorded_line(json, "line_before"), la = supervisor::recorded_line(json, "line_after");
    if (before.empty() || after.empty() || !lb || !la) continue;
    for (int repeat = 0; repeat < 5; ++repeat) {
      const double start = ex::thread_cpu_ms();
      segmenter.segment(before, after, *lb, *la);
      ms.push_back(ex::thread_cpu_ms() - start);
    }
  }
  return ms.empty() ? 0 : ex::median(ms);
}

// One set of scenes (held-out or development): its runs, aggregates, table and gallery rows.
struct SetScore {
  std::vector<Run> runs;
  std::vector<fs::path> attempt_dirs;
  int single_runs = 0, successes = 0, effector = 0, tool_changed = 0, phantoms = 0, multi_found = 0, multi_present = 0;
  int segmented_fallen = 0, objects_fallen = 0;  // Run's, summed
  int multi_in_reach = 0, multi_found_in_reach = 0;  // the same, over the objects within the workspace ring
  std::vector<std::string> beyond_reach;             // "run: object i at r mm" for the objects outside it
  std::vector<double> ious;
  std::vector<double> refused_ious;  // of the masks the supervisor refused (Run::refused)
  int refused_good() const {
    return static_cast<int>(std::count_if(refused_ious.begin(), refused_ious.end(), [](double iou) { return iou >= 0.5; }));
  }
  std::string table;
  std::vector<cv::Mat> gallery;
  double mean_iou() const { return ious.empty() ? 0 : ex::mean(ious); }
  double min_iou() const { return ious.empty() ? 0 : *std::min_element(ious.begin(), ious.end()); }
};

std::vector<std::string> scene_names(const fs::path& scene_dir) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(scene_dir))
    if (entry.path().extension() == ".yaml") names.push_back(entry.path().stem().string());
  std::sort(names.begin(), names.end());
  return names;
}

// How the runs detected their candidates: the symmetry and triangulation services' flags, read
// from the first run's launch file (services/launch.json, written by nudge_run_loop), so that the
// figures say which pipeline (NUDGE_LOOP_TABLE: verified, plain or busy) they measure.
struct Detection {
  // "verified" (accumulator peaks verified, the upright check), "busy" (the same on colour edges),
  // "plain" (the thesis'); "+ column mask" when the arm's base column was left out of the edges.
  std::string pipeline = "unknown";
  std::string flags;                 // markdown: each service's command line without its binary's path
};
Detection detection_of(const fs::path& runs_dir) {
  Detection d;
  if (!fs::is_directory(runs_dir)) return d;
  std::vector<fs::path> files;
  for (const auto& scene : fs::directory_iterator(runs_dir)) {
    const fs::path file = scene.path() / scene.path().filename() / "services" / "launch.json";
    if (fs::exists(file)) files.push_back(file);
  }
  if (files.empty()) return d;
  std::sort(files.begin(), files.end());
  std::ifstream in(files.front());
  const nlohmann::json launch = nlohmann::json::parse(in, nullptr, false);
  if (launch.is_discarded() || !launch.contains("processes")) return d;
  bool verified = false, colour_edges = false, column_mask = false;
  for (const auto& process : launch["processes"]) {
    const std::string name = process.value("name", "");
    if (name != "symmetry" && name != "triangulation") continue;
    std::string line = "`nudge-" + name;
    const auto& command = process["command"];
    for (size_t i = 1; i < command.size(); ++i) {
      const std::string arg = command[i].get<std::string>();
      line += " " + (arg.find('/') != std::string::npos ? fs::path(arg).filename().string() : arg);
      verified = verified || arg == "--verify";
      colour_edges = colour_edges || arg == "--colour-edges";
      column_mask = column_mask || arg == "--column-calibration";
    }
    d.flags += (d.flags.empty() ? "" : "; ") + line + "`";
  }
  if (d.flags.empty()) return d;
  d.pipeline = !verified ? "plain" : colour_edges ? "busy" : "verified";
  if (column_mask) d.pipeline += " + column mask";
  return d;
}

std::string join(const std::vector<std::string>& parts, const std::string& separator) {
  std::string out;
  for (const std::string& p : parts) out += (out.empty() ? "" : separator) + p;
  return out;
}

SetScore score_set(const fs::path& runs_dir, const fs::path& scene_dir, std::vector<std::string> names,
                   const robot::Workspace& workspace) {
  if (names.empty()) names = scene_names(scene_dir);
  SetScore set;
  nudge::Progress progress("nudge-exp-nudge-segmentation", static_cast<int>(names.size()));
  for (const std::string& name : names) {
    progress.step(name);
    const fs::path run_dir = runs_dir / name / name;
    if (!fs::exists(run_dir / "summary.json")) {
      progress.note(name + ": no run in " + run_dir.string() + " (skipped)");
      continue;
    }
    set.runs.push_back(evaluate(name, run_dir, scene_dir / (name + ".yaml"), workspace));
    for (const auto& entry : fs::directory_iterator(run_dir))
      if (entry.is_directory() && entry.path().filename().string().rfind("attempt_", 0) == 0) set.attempt_dirs.push_back(entry.path());
  }
  progress.finish(std::to_string(set.runs.size()) + " runs read");
  std::sort(set.attempt_dirs.begin(), set.attempt_dirs.end());

  std::ostringstream table;
  std::vector<std::string> refusals;  // "run attempt N (object k, IoU x): why it was refused"
  table << "| run | objects | attempts | segmented (object: IoU) | effector px | no motion | tipped | other | refused masks (object: IoU) | fallen: segmented, at the end | wall s | end |\n"
        << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const Run& r : set.runs) {
    if (r.objects_present > 1) {
      set.multi_found += static_cast<int>(r.objects_found.size());
      set.multi_present += r.objects_present;
      set.multi_in_reach += r.objects_present - static_cast<int>(r.objects_beyond_reach.size());
      for (int object : r.objects_found) set.multi_found_in_reach += !r.objects_beyond_reach.count(object);
      for (int object : r.objects_beyond_reach)
        set.beyond_reach.push_back(r.name + " object " + std::to_string(object) + (r.objects_found.count(object) ? " (segmented)" : ""));
    } else {
      ++set.single_runs;
      set.successes += r.success();
    }
    set.phantoms += r.no_motion;
    set.segmented_fallen += r.segmented_fallen;
    set.objects_fallen += static_cast<int>(r.objects_fallen.size());
    const std::string segmented = objects_and_ious(r.segmented), refused = objects_and_ious(r.refused);
    int run_effector = 0;
    for (const Segmented& s : r.segmented) {
      set.ious.push_back(s.iou);
      run_effector += s.effector_pixels;
      set.tool_changed += s.tool_changed_pixels;
      if (!s.gallery.empty()) set.gallery.push_back(s.gallery);
    }
    set.effector += run_effector;
    for (const Segmented& s : r.refused) {
      set.refused_ious.push_back(s.iou);
      char text[64];
      std::snprintf(text, sizeof text, "%s attempt %d (object %d, IoU %.3f): ", r.name.c_str(), s.attempt, s.object, s.iou);
      refusals.push_back(text + s.reason);
    }
    char wall[32];
    std::snprintf(wall, sizeof wall, "%.0f", r.wall_s);
    table << "| " << r.name << " | " << r.objects_present << " | " << r.attempts << " | "
          << segmented << " | " << run_effector << " | " << r.no_motion << " | " << r.tipped
          << " | " << r.other_failures << " | " << refused << " | " << r.segmented_fallen << ", " << r.objects_fallen.size() << " | " << wall << " | " << r.end_reason << " |\n";
  }
  std::vector<std::string> falls;
  for (const Run& r : set.runs)
    for (const std::string& fall : r.falls) falls.push_back(r.name + ": " + fall);
  if (!falls.empty()) table << "\nObjects that fell (the first recorded state showing each lying): " << join(falls, "; ") << ".\n";
  if (!refusals.empty()) table << "\nMasks refused: " << join(refusals, "; ") << ".\n";
  set.table = table.str();
  return set;
}

void json_fields(JsonWriter& j, const SetScore& s, double ms) {
  j.field("runs", s.single_runs).field("successes", s.successes).field("mean_iou", s.mean_iou()).field("min_iou", s.min_iou());
  j.field("segmentations", static_cast<int>(s.ious.size())).field("effector_pixels", s.effector);
  j.field("tool_changed_pixels", s.tool_changed);
  j.field("mean_ms_motion_segmentation", ms).field("multi_object_found", s.multi_found).field("multi_object_present", s.multi_present);
  j.field("multi_object_in_reach", s.multi_in_reach).field("multi_object_found_in_reach", s.multi_found_in_reach);
  j.field("phantoms_rejected", s.phantoms);
  j.field("segmentations_of_fallen_objects", s.segmented_fallen).field("objects_fallen", s.objects_fallen);
  j.field("refused_masks", static_cast<int>(s.refused_ious.size())).field("refused_masks_iou_at_least_half", s.refused_good());
}

std::string figures_table(const SetScore& s, double ms) {
  std::ostringstream md;
  md << "| figure | thesis | here |\n|---|---|---|\n"
     << "| single-object runs with the object segmented | 12/12 | " << s.successes << "/" << s.single_runs << " |\n";
  char line[256];
  std::snprintf(line, sizeof line, "| mean IoU (min) of every segmentation | – | %.3f (%.3f) over %zu |\n", s.mean_iou(), s.min_iou(), s.ious.size());
  md << line;
  std::snprintf(line, sizeof line, "| motion segmentation, ms per 1280x960 pair (one thread, CPU time, median) | 80 | %.1f |\n", ms);
  md << line << "| end-effector pixels in the masks (the pad's or gripper's own) | – | " << s.effector << " |\n"
     << "| mask pixels the tool changes (itself and its shadow; the count reported before 2026-11-25) | – | " << s.tool_changed << " |\n"
     << "| objects of the multi-object scenes segmented | (one object per scene) | " << s.multi_found << "/" << s.multi_present << " |\n"
     << "| of them standing within the arm's workspace ring, segmented | – | " << s.multi_found_in_reach << "/" << s.multi_in_reach
     << (s.beyond_reach.empty() ? std::string() : " (outside the ring: " + join(s.beyond_reach, ", ") + ")") << " |\n"
     << "| attempts that found no motion (phantoms, out-of-view) | – | " << s.phantoms << " |\n"
     << "| segmentations of an object lying fallen (leaning over " << kFallenDeg << " deg in the simulator; not counted as segmented) | – | "
     << s.segmented_fallen << " |\n"
     << "| objects lying fallen at the runs' ends | – | " << s.objects_fallen << " |\n"
     << "| masks the supervisor cut and refused (its shape checks), of them IoU 0.5 or more | – | " << s.refused_ious.size() << ", "
     << s.refused_good() << " |\n";
  return md.str();
}

}  // namespace

int main(int argc, char** argv) {
  // nudge-exp-nudge-segmentation RUNS_DIR SCENE_DIR [RUN...] [--development RUNS_DIR SCENE_DIR]
  std::vector<std::string> args(argv + 1, argv + argc);
  std::optional<std::pair<fs::path, fs::path>> development;
  std::string name = "nudge_segmentation";  // --name: the result files' stem
  for (size_t i = 0; i < args.size(); ++i)
    if (args[i] == "--name") {
      if (i + 1 >= args.size() || args[i + 1].empty() || args[i + 1].find('/') != std::string::npos) {
        std::cerr << "--name needs a file name stem (no '/')\n";
        return 2;
      }
      name = args[i + 1];
      args.erase(args.begin() + static_cast<long>(i), args.begin() + static_cast<long>(i) + 2);
      break;
    }
  // --development-set: the first set is a development set (tuned on), and its report says so.
  const auto development_flag = std::find(args.begin(), args.end(), "--development-set");
  const bool first_set_is_development = development_flag != args.end();
  if (first_set_is_development) args.erase(development_flag);
  robot::Workspace workspace;  // --workspace FILE: the ring the objects are counted in reach by
  for (size_t i = 0; i < args.size(); ++i)
    if (args[i] == "--workspace") {
      if (i + 1 >= args.size()) {
        std::cerr << "--workspace needs a workspace file\n";
        return 2;
      }
      try {
        workspace = robot::load_workspace(args[i + 1]);
      } catch (const std::exception& e) {
        std::cerr << e.what() << "\n";
        return 2;
      }
      args.erase(args.begin() + static_cast<long>(i), args.begin() + static_cast<long>(i) + 2);
      break;
    }
  for (size_t i = 0; i < args.size(); ++i)
    if (args[i] == "--development") {
      if (i + 2 >= args.size()) {
        std::cerr << "--development needs RUNS_DIR SCENE_DIR\n";
        return 2;
      }
      development = std::make_pair(fs::path(args[i + 1]), fs::path(args[i + 2]));
      args.erase(args.begin() + static_cast<long>(i), args.begin() + static_cast<long>(i) + 3);
      break;
    }
  if (first_set_is_development && development) {
    std::cerr << "--development-set and --development: the first set is already a development set; score one set\n";
    return 2;
  }
  if (args.size() < 2) {
    std::cerr << "usage: nudge-exp-nudge-segmentation RUNS_DIR SCENE_DIR [RUN...] [--development RUNS_DIR SCENE_DIR] [--name STEM]\n"
                 "         [--workspace FILE] [--development-set]  (the workspace ring objects count as in reach by; default: the code's)\n"
                 "  (the first set gives the headline figures: the held-out scenes, or with --development-set a\n"
                 "  development set's; STEM.json, STEM.md in docs/results,\n"
                 "  default nudge_segmentation)\n";
    return 2;
  }
  const fs::path runs_dir = args[0], scene_dir = args[1];
  const std::vector<std::string> names(args.begin() + 2, args.end());
  const SetScore main_set = score_set(runs_dir, scene_dir, names, workspace);
  std::optional<SetScore> dev_set;
  if (development) dev_set = score_set(development->first, development->second, {}, workspace);
  std::vector<fs::path> attempt_dirs = main_set.attempt_dirs;
  if (dev_set) attempt_dirs.insert(attempt_dirs.end(), dev_set->attempt_dirs.begin(), dev_set->attempt_dirs.end());
  const double ms = time_motion_segmentation(attempt_dirs);

  JsonWriter j(4);
  j.begin_object();
  const Detection detection = detection_of(runs_dir);
  j.field("scenes", scene_dir.filename().string()).field("detection", detection.pipeline);
  json_fields(j, main_set, ms);
  j.field("set_kind", first_set_is_development ? "development" : "held-out");
  j.field("machine", ex::machine_description()).field("date", ex::today());
  if (dev_set) {
    j.key("development").begin_object();
    j.field("scenes", development->second.filename().string());
    json_fields(j, *dev_set, ms);
    j.end_object();
  }
  j.end_object();
  ex::write_result(name + ".json", j.str() + "\n");

  // The first set's heading and the gallery's order name what kind of set it is.
  const std::string first_set_heading = first_set_is_development ? "Development scenes, tuned on" : "Held-out scenes";
  const std::string gallery_order = first_set_is_development ? "development scenes" : "held-out scenes, then development";
  std::ostringstream md;
  md << "# Autonomous segmentation by a robotic nudge (thesis sec. 6.5, in simulation)\n\n"
     << "`experiments/nudge_segmentation.sh` runs the whole loop (world, camera with stills, symmetry, triangulation, "
        "arm, supervisor: every service its own process over LCM in a private network namespace) on each scene of two "
        "sets: **held-out** scenes (`h*` single objects, `hm*` several; written by "
        "`nudge-exp-nudge-segmentation-scenes` from seeds fixed before any run on them and never re-staged: "
        "`experiments/scenes/nudge_segmentation_heldout/` from 610001-610015, fixed on 2026-11-24; "
        "`nudge_segmentation_heldout2/` from 620001-620015, fixed on 2026-11-25 after the first set's failures had "
        "been looked into) give the headline figures; the **development** scenes "
        "`experiments/scenes/nudge_segmentation/` (`s*`, `m*`: reported once, then used to find and fix the failures) "
        "follow. `nudge-exp-nudge-segmentation` scores each segmentation against the simulator's truth: the recorded "
        "state at the after still re-rendered at 1280x960 (label mask, handles included); the object the mask overlaps "
        "most is the one segmented.\n\n"
     << ex::machine_description() << ", " << ex::today() << ".\n\n"
     << "Detection: the **" << detection.pipeline << "** pipeline (`NUDGE_LOOP_TABLE`, `scripts/lib.sh`): " << detection.flags
     << ".\n\n"
     << "## " << first_set_heading << " (`" << scene_dir.filename().string() << "`)\n\n" << figures_table(main_set, ms) << "\n"
     << main_set.table << "\n";
  if (dev_set)
    md << "## Development scenes (`" << development->second.filename().string() << "`)\n\n" << figures_table(*dev_set, ms)
       << "\n" << dev_set->table << "\n";
  md << "`segmented`: scene index of the object covered and the mask's IoU with its true mask. `other`: attempts "
        "refused by the arm, segmentations that came out empty or were refused, lost stills. `refused masks`: the "
        "masks the supervisor cut and refused (too small, thin, not mirrored, sides off the still's edges; counted "
        "under `other`), scored against the truth at the state recorded when the attempt began to segment. The "
        "motion segmentation time is over both sets' stills.\n\n"
     << "## Gallery\n\nPer segmentation (" << gallery_order << "): before, after, the mask over the after still.\n\n"
     << "![gallery](" << name << "_gallery.png)\n";
  ex::write_result(name + ".md", md.str());
  std::vector<cv::Mat> gallery = main_set.gallery;
  if (dev_set) gallery.insert(gallery.end(), dev_set->gallery.begin(), dev_set->gallery.end());
  if (!gallery.empty()) ex::write_png(name + "_gallery.png", ex::tile(gallery, 2));
  std::cerr << main_set.successes << "/" << main_set.single_runs << " single-object runs segmented, mean IoU " << main_set.mean_iou()
            << ", multi-object " << main_set.multi_found << "/" << main_set.multi_present << ", motion segmentation " << ms << " ms\n";
  if (dev_set)
    std::cerr << "development: " << dev_set->successes << "/" << dev_set->single_runs << ", mean IoU " << dev_set->mean_iou()
              << ", multi-object " << dev_set->multi_found << "/" << dev_set->multi_present << "\n";
  return 0;
}
