// The object-learning experiment (thesis sec. 7.4, Table 7.1; issue 11), scored. The seven
// bottles were learned by experiments/learning.sh, one run of the whole chain each, into one object
// database; this program
//   - reads each run's summary (learned or not, and why; the grasp's plan time),
//   - recognises the 28 test images and the 10 images of objects never learned (written by
//     nudge-exp-learning-scenes --set eval, seeds fixed in advance) with the learner's Recognizer,
//   - judges every verified match against the simulator's truth: good when the test image's
//     keypoint and the training view's keypoint lie on the same surface point of the object
//     (learning::judge_matches). The test side's surface coordinates were rendered with the test
//     image; the training side's are rendered again from the run's LCM log: the camera service
//     drew each training view as World::render_snapshot(right) after apply_poses(SIM_STATE at the
//     view's utime), and the same calls on the same scene give that view's render_snapshot_surface,
//   - times recognition of one test image against the learned objects padded to 100.
//   nudge-exp-learning --runs DIR --scenes DIR --test-images DIR [--tolerance-mm 5] [--name learning]
// Writes docs/results/NAME.{json,md}, NAME_views.png (the training views of one object) and
// NAME_match_*.png (fig. 7.10).
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <set>
#include <sstream>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "learning_scenes.hpp"
#include "learning_timing.hpp"
#include "nudge/bus/sim_convert.hpp"
#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/learning/database.hpp"
#include "nudge/learning/match_truth.hpp"
#include "nudge/learning/recognizer.hpp"
#include "nudge/learning/synthetic.hpp"
#include "nudge/sim/scene.hpp"
#include "nudge/sim/state_sync.hpp"
#include "nudge/sim/world.hpp"
#include "nudge/sim_state_t.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace fs = std::filesystem;

namespace {

constexpr int kTimingRuns = 3;
constexpr int kPaddedObjects = 100;
constexpr uint64_t kStandInSeed = 3000;  // synthetic stand-ins 3000..3099: unused by tests, bench, learning_box

// Thesis Table 7.1 (real bottles; sec. 7.4): 28/28 correct, and per bottle the good and bad matches
// of its four images summed (the thesis judged them by eye). Its "glass" bottle is the reflective
// one here, its "cola" bottle the half-transparent one.
constexpr int kThesisCorrect = 28;
struct ThesisRow { const char* bottle; int good, bad; };
constexpr ThesisRow kThesisTable[] = {{"white_bottle", 46, 0},      {"yellow_bottle", 53, 0},
                                      {"green_bottle", 64, 3},      {"brown_bottle", 55, 0},
                                      {"reflective_bottle", 19, 3}, {"half_transparent_bottle", 31, 0},
                                      {"transparent_bottle", 30, 1}};

const ThesisRow* thesis_row(const std::string& bottle) {
  for (const ThesisRow& r : kThesisTable)
    if (bottle == r.bottle) return &r;
  return nullptr;
}

struct Options {
  std::string runs, scenes, test_images, name = "learning", set = "eval";
  double tolerance_mm = 5;
  // Learn every stored object again from its stored training views with `learn` (the learner's
  // defaults unless flags say otherwise): the database as today's learner would have written it
  // from the same views, so that a change to learning is measured without re-running the arm.
  bool relearn = false;
  // With relearn: the learner's scene still (the attempt's after still) for pruning, as the
  // service had it; with table_view the after still is one more view instead (the object standing
  // on the table, its right mask's box) and the before still prunes (a diagnosis: what a view at
  // the test images' own scale, with no fingers on the label, would add).
  bool table_view = false;
  // With relearn: the standing (or table) view keeps only the keypoints inside the right
  // segmentation (learn_view_t::mask); off: the box alone, as before the mask was sent.
  bool view_mask = true;
  // With relearn, runs recorded with the supervisor's standing view: learn without it (the 12
  // turned views, pruned against the after still), as the learner would have had them.
  bool drop_standing_view = false;
  learning::LearnParams learn;
  learning::RecognizeParams recognize;  // the learner's defaults unless flags say otherwise
};

// The model learn_object makes from a stored model's training images, boxes and wrist angles, with
// the scene still of its attempt (runs/<run_id>/<run_id>/<object_key>/, as the learner had it) and,
// with `table_view`, its after still as one more view (see Options::table_view).
std::shared_ptr<const learning::ObjectModel> relearned(const learning::ObjectModel& stored,
                                                       const learning::LearnParams& params, const std::string& runs_dir,
                                                       bool table_view, bool view_mask, bool drop_standing_view) {
  std::vector<learning::TrainingImage> images;
  for (const learning::ModelView& v : stored.views) {
    if (v.image.empty()) throw std::runtime_error(stored.info.name + ": a training view without its image");
    images.push_back({v.image, v.box, v.wrist_angle, v.mask});
  }
  const fs::path attempt = fs::path(runs_dir) / stored.info.run_id / stored.info.run_id / stored.info.object_key;
  auto read = [&attempt](const char* file, int flags) {
    cv::Mat image = cv::imread((attempt / file).string(), flags);
    if (image.empty()) throw std::runtime_error((attempt / file).string() + ": cannot read");
    return image;
  };
  // The supervisor's standing view (its after still as the last view, Config::standing_view) was
  // pruned against the before still; without it the learner had the after still.
  const cv::Mat after = read("after.png", cv::IMREAD_COLOR);
  const cv::Mat& last = images.back().image;
  bool standing = last.size() == after.size() && last.type() == after.type() && cv::norm(last, after, cv::NORM_INF) == 0;
  if (standing && drop_standing_view) {  // as the learner would have learned without it
    images.pop_back();
    standing = false;
  }
  const cv::Mat right_mask = standing || table_view ? read("mask.png", cv::IMREAD_GRAYSCALE) : cv::Mat();
  if (table_view && !standing) {
    images.push_back({after, cv::boundingRect(right_mask), 0, {}});
    standing = true;
  }
  // The standing view's keypoints are kept only inside the right segmentation (as the learner does
  // with the mask the supervisor sends); a run stored before the mask was sent has it in mask.png.
  if (standing) {
    cv::Mat& mask = images.back().mask;
    if (!view_mask) mask.release();
    else if (mask.empty()) mask = right_mask;
  }
  const cv::Mat scene = standing ? read("before.png", cv::IMREAD_COLOR) : after;
  learning::LearnStats stats;
  const auto start = std::chrono::steady_clock::now();
  auto model = std::make_shared<learning::ObjectModel>(learning::learn_object(stored.info, images, params, &stats, {}, scene));
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  std::cerr << "relearned " << stored.info.name << " in " << std::lround(ms) << " ms: " << stats.detected << " detected, " << stats.outside_box
            << " outside the box, " << stats.outside_mask << " off the mask, " << stats.background << " background, "
            << stats.scene << " in the scene still, " << stats.kept << " kept (stored: "
            << stored.descriptor_count() << ")\n";
  return model;
}

// Times by stage, in the order the stages were first seen (the order the plan runs them).
using StageTimes = std::vector<std::pair<std::string, std::vector<double>>>;

void add_stage_times(StageTimes& stages, const std::string& stage, const std::vector<double>& ms) {
  auto it = std::find_if(stages.begin(), stages.end(), [&](const auto& s) { return s.first == stage; });
  if (it == stages.end()) it = stages.insert(stages.end(), {stage, {}});
  it->second.insert(it->second.end(), ms.begin(), ms.end());
}

// One training scene's run, as its summary tells it.
struct Run {
  std::string scene, bottle;          // train1_white_bottle, white_bottle
  sim::ObjectSpec bottle_spec;        // the training scene's first object
  fs::path folder;                    // runs/<scene>/<scene>
  std::string learned_name;           // in the database; "" when not learned
  std::string why_not;                // what happened instead
  std::vector<int64_t> view_utimes;   // of the learning attempt's views, in view order
  std::vector<double> grasp_plan_ms;  // every grasp the run commanded
  std::vector<double> grasp_plan_cpu_ms;  // ... the supervisor thread's CPU time (runs since 2026-12-02)
  StageTimes grasp_plan_stages_ms;  // ... by stage (runs since 2026-12-03)
  int attempts = 0;
  double wall_s = 0;
  fs::path most_views;                // attempt_NN/views of the attempt that took the most views
  int most_views_count = 0;
};

// One test image recognised and judged.
struct Judged {
  std::string image, target, variant, label, bottle;  // bottle: what the label is (a learned bottle)
  int verified = 0, good = 0, bad = 0, best_view = -1;
  bool unjudged = false;  // the best view is the --table-view one, which has no re-rendered truth
  int most_ratio_matches = 0, most_verified = 0;  // over every object, recognised or not (why not: how near)
  int label_pixels = -1;  // the target's label pixels in sight (-1: no target, or it has no label)
  std::vector<double> distances_m;
  learning::Recognition recognition;
};

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string attempt_story(const nlohmann::json& a) {
  std::string story = "attempt " + std::to_string(a.value("attempt", 0)) + ": " + a.value("reason", std::string());
  if (a.contains("learning") && !a["learning"].value("recognised", std::string()).empty())
    story += " (recognised as " + a["learning"]["recognised"].get<std::string>() + ")";
  return story;
}

Run read_run(const fs::path& runs, const fs::path& scene_file) {
  Run run;
  run.scene = scene_file.stem().string();
  run.bottle_spec = sim::load_scene(scene_file.string()).objects.at(0);
  run.bottle = run.bottle_spec.name;
  run.folder = runs / run.scene / run.scene;
  const fs::path summary_file = run.folder / "summary.json";
  if (!fs::exists(summary_file)) {
    run.why_not = "no run (" + summary_file.string() + " missing)";
    return run;
  }
  const nlohmann::json summary = nlohmann::json::parse(read_text(summary_file));
  run.attempts = summary.value("attempts", 0);
  std::string stories;
  for (const auto& a : summary.at("attempt_list")) {
    stories += (stories.empty() ? "" : "; ") + attempt_story(a);
    if (!a.contains("learning")) continue;
    const auto& l = a["learning"];
    if (l.value("grasp_plan_ms", -1.0) >= 0) run.grasp_plan_ms.push_back(l["grasp_plan_ms"].get<double>());
    if (l.value("grasp_plan_cpu_ms", -1.0) >= 0) run.grasp_plan_cpu_ms.push_back(l["grasp_plan_cpu_ms"].get<double>());
    if (l.contains("grasp_plan_stages_ms"))
      for (const auto& stage : l["grasp_plan_stages_ms"])
        add_stage_times(run.grasp_plan_stages_ms, stage.at("stage").get<std::string>(), {stage.at("ms").get<double>()});
    const int views = static_cast<int>(l.value("views", nlohmann::json::array()).size());
    if (views > run.most_views_count) {
      run.most_views_count = views;
      char folder[32];
      std::snprintf(folder, sizeof folder, "attempt_%02d", a.value("attempt", 0));
      run.most_views = run.folder / folder / "views";
    }
    if (l.value("outcome", std::string()) != "learned" || !run.learned_name.empty()) continue;
    run.learned_name = l.value("learned_name", std::string());
    for (const auto& v : l.at("views")) run.view_utimes.push_back(v.at("utime").get<int64_t>());
  }
  if (run.learned_name.empty())
    run.why_not = (stories.empty() ? "no attempt" : stories) + "; run ended: " + summary.value("end_reason", std::string());
  const std::string wall = read_text(run.folder / "wall_seconds.txt");
  run.wall_s = wall.empty() ? 0 : std::stod(wall);
  return run;
}

// The right camera's training views of a run as the camera service drew them: the view's colour
// image and surface truth, re-rendered from the SIM_STATE the view was taken at.
struct TrainingTruth {
  std::vector<learning::SurfaceTruth> views;
  std::vector<double> colour_difference;  // mean |re-render - stored view| per view, grey levels
};

TrainingTruth render_training_views(const Run& run, const fs::path& scene_file, const learning::ObjectDatabase& db) {
  std::map<int64_t, sim_state_t> states;
  for (int64_t t : run.view_utimes) states[t];
  const std::string log_file = (run.folder / (run.scene + ".lcmlog")).string();
  lcm::LogFile log(log_file, "r");
  if (!log.good()) throw std::runtime_error(log_file + ": cannot open the run's log");
  std::set<int64_t> found;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != "SIM_STATE") continue;
    sim_state_t s;
    if (s.decode(e->data, 0, e->datalen) < 0 || !states.count(s.utime)) continue;
    states[s.utime] = s;
    found.insert(s.utime);
  }
  sim::World world(sim::load_scene(scene_file.string()));
  TrainingTruth truth;
  for (size_t k = 0; k < run.view_utimes.size(); ++k) {
    const int64_t t = run.view_utimes[k];
    if (!found.count(t)) throw std::runtime_error(log_file + ": no SIM_STATE at view " + std::to_string(k) + "'s utime " + std::to_string(t));
    sim::apply_poses(world, bus::poses_of(states[t]));
    learning::SurfaceTruth view;
    view.surface = world.render_snapshot_surface(1, &view.mask);
    view.label = 1;  // the training scene's one object
    view.object = run.bottle;
    // Check of the re-render: the stored training view against the same state drawn again.
    cv::Mat stored = db.load_view_image(run.learned_name, static_cast<int>(k)), drawn = world.render_snapshot(1);
    if (stored.channels() == 1) cv::cvtColor(stored, stored, cv::COLOR_GRAY2BGR);
    if (stored.size() != drawn.size())
      throw std::runtime_error(run.learned_name + " view " + std::to_string(k) + ": stored " + std::to_string(stored.cols) +
                               " px wide, the re-render " + std::to_string(drawn.cols));
    cv::Mat diff;
    cv::absdiff(stored, drawn, diff);
    const cv::Scalar per_channel = cv::mean(diff);
    truth.colour_difference.push_back((per_channel[0] + per_channel[1] + per_channel[2]) / 3);
    truth.views.push_back(std::move(view));
  }
  return truth;
}

// How much of the target's label the test image shows: its pixels whose object-frame height lies in
// the label's band. The bottles' bodies are plain; their labels carry nearly all of their SIFT
// features, so an image showing little label has little to be recognised by.
// `bottles`: the learned bottles' specs by name (the training scenes' first objects).
int label_pixels_in_sight(const TestImage& t, const std::map<std::string, sim::ObjectSpec>& bottles) {
  const auto found = bottles.find(t.target);
  if (found == bottles.end() || !found->second.label.present() || t.surface.type() != CV_32FC3 ||
      t.mask.type() != CV_8U || t.mask.size() != t.surface.size())
    return -1;
  const auto [bottom, top] = sim::label_band(found->second);
  cv::Mat height;
  cv::extractChannel(t.surface, height, 2);
  return cv::countNonZero((t.mask == 1) & (height >= bottom) & (height <= top));
}

Judged recognise_and_judge(const learning::Recognizer& recognizer, const TestImage& t,
                           const std::map<std::string, sim::ObjectSpec>& bottles,
                           const std::map<std::string, std::string>& bottle_of,
                           std::map<std::string, TrainingTruth>& training, double tolerance_m) {
  Judged j;
  j.image = t.name;
  j.target = t.target;
  j.variant = variant_name(t.variant);
  j.recognition = recognizer.recognize(t.colour);
  j.label_pixels = label_pixels_in_sight(t, bottles);
  for (const learning::ObjectScore& score : j.recognition.scores) {
    j.most_ratio_matches = std::max(j.most_ratio_matches, score.ratio_matches);
    j.most_verified = std::max(j.most_verified, score.verified_matches);
  }
  const learning::ObjectScore* best = j.recognition.best_score();
  if (!best) return j;
  j.label = best->name;
  j.bottle = bottle_of.at(best->name);
  j.verified = best->verified_matches;
  j.best_view = best->best_view;
  const learning::SurfaceTruth query{t.surface, t.mask, 1, t.target.empty() ? t.name : t.target};
  const TrainingTruth& views = training.at(best->name);
  if (best->best_view == static_cast<int>(views.views.size())) {  // the --table-view view
    j.unjudged = true;
    return j;
  }
  if (best->best_view < 0 || best->best_view >= static_cast<int>(views.views.size()))
    throw std::runtime_error(best->name + ": best view " + std::to_string(best->best_view) + " has no re-rendered truth");
  const learning::MatchVerdicts v =
      learning::judge_matches(best->matches, j.recognition.query.keypoints, query,
                              recognizer.find(best->name)->views[best->best_view].features.keypoints,
                              views.views[best->best_view], tolerance_m);
  j.good = v.good;
  j.bad = v.bad;
  j.distances_m = v.distances_m;
  return j;
}

cv::Mat thumbnail(cv::Mat view, int k) {
  if (view.channels() == 1) cv::cvtColor(view, view, cv::COLOR_GRAY2BGR);
  cv::Mat small;
  cv::resize(view, small, cv::Size(320, 240), 0, 0, cv::INTER_AREA);
  cv::putText(small, "view " + std::to_string(k), cv::Point(5, 20), cv::FONT_HERSHEY_SIMPLEX, 0.6, cv::Scalar(0, 0, 0), 2);
  return small;
}

// The training views of one object, 6 a row, each with its box (green) and the descriptors kept
// (red) (thesis fig. 7.6).
cv::Mat views_sheet(const learning::ObjectDatabase& db, const learning::ObjectModel& m) {
  std::vector<cv::Mat> thumbs;
  for (size_t k = 0; k < m.views.size(); ++k) {
    // A relearned model holds its images (and --table-view's extra one is only there).
    cv::Mat view = m.views[k].image.empty() ? db.load_view_image(m.info.name, static_cast<int>(k)) : m.views[k].image.clone();
    if (view.channels() == 1) cv::cvtColor(view, view, cv::COLOR_GRAY2BGR);
    cv::rectangle(view, m.views[k].box, cv::Scalar(0, 200, 0), 3);
    for (const cv::KeyPoint& p : m.views[k].features.keypoints) cv::circle(view, p.pt, 4, cv::Scalar(0, 0, 255), 2);
    thumbs.push_back(thumbnail(view, static_cast<int>(k)));
  }
  return tile(thumbs, 6);
}

// Nothing learned: the views a run took before its attempt ended, as the supervisor saved them.
cv::Mat taken_views_sheet(const Run& run) {
  std::vector<cv::Mat> thumbs;
  for (int k = 0; k < run.most_views_count; ++k) {
    char file[32];
    std::snprintf(file, sizeof file, "view_%02d.png", k);
    const cv::Mat view = cv::imread((run.most_views / file).string());
    if (!view.empty()) thumbs.push_back(thumbnail(view, k));
  }
  return thumbs.empty() ? cv::Mat() : tile(thumbs, 6);
}

std::string fixed(double v, int decimals = 1) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << v;
  return s.str();
}

cv::Mat at_most_wide(const cv::Mat& image, int width) {
  if (image.cols <= width) return image;
  cv::Mat out;
  cv::resize(image, out, cv::Size(), static_cast<double>(width) / image.cols, static_cast<double>(width) / image.cols,
             cv::INTER_AREA);
  return out;
}

double max_of(const std::vector<double>& v) { return v.empty() ? 0 : *std::max_element(v.begin(), v.end()); }

// The question the supervisor asks before it nudges a candidate, asked of every training scene:
// the first attempt's before still (the bottle standing where the run found it, the arm's base
// column behind it) recognised against every learned object but the bottle's own. Taken for
// another object, the bottle counts as known and is never learned in a run after that object's
// (the standing view's first chain run, docs/learning.md rule 5).
struct SceneCheck {
  std::string bottle, taken_for;  // taken_for: "" when nothing else was recognised
  int verified = 0;
};

// The before still of the run's first attempt that has one; empty when none has.
cv::Mat first_before_still(const Run& run) {
  std::vector<fs::path> attempts;
  if (fs::is_directory(run.folder))
    for (const auto& e : fs::directory_iterator(run.folder))
      if (e.is_directory() && e.path().filename().string().rfind("attempt_", 0) == 0) attempts.push_back(e.path());
  std::sort(attempts.begin(), attempts.end());
  for (const fs::path& a : attempts)
    if (fs::exists(a / "before.png")) return cv::imread((a / "before.png").string(), cv::IMREAD_COLOR);
  return cv::Mat();
}

std::vector<SceneCheck> check_training_scenes(learning::Recognizer& recognizer, const std::vector<Run>& runs,
                                              const std::vector<std::shared_ptr<const learning::ObjectModel>>& models,
                                              const std::map<std::string, std::string>& bottle_of) {
  std::vector<SceneCheck> checks;
  for (const Run& run : runs) {
    const cv::Mat before = first_before_still(run);
    if (before.empty()) continue;
    std::shared_ptr<const learning::ObjectModel> own;
    for (const auto& m : models)
      if (!run.learned_name.empty() && m->info.name == run.learned_name) own = m;
    if (own) recognizer.remove(own->info.name);
    const learning::Recognition r = recognizer.recognize(before);
    if (own) recognizer.add(own);
    SceneCheck c;
    c.bottle = run.bottle;
    if (const learning::ObjectScore* best = r.best_score()) c.taken_for = bottle_of.at(best->name), c.verified = best->verified_matches;
    checks.push_back(c);
  }
  return checks;
}

struct Totals {
  int objects_learned = 0, test_images = 0, correct = 0, wrong = 0, unrecognised = 0, good = 0, bad = 0;
  int unknown_images = 0, false_recognitions = 0, correct_of_learned = 0, test_images_of_learned = 0;
  std::vector<double> grasp_plan_ms, grasp_plan_cpu_ms, distances_m;
  StageTimes grasp_plan_stages_ms;
  std::vector<SceneCheck> training_scenes;
  int training_scenes_taken = 0;  // of them, taken for another object
};

Totals add_up(const std::vector<Run>& runs, const std::vector<Judged>& judged) {
  Totals t;
  std::set<std::string> learned;
  for (const Run& r : runs) {
    if (!r.learned_name.empty()) learned.insert(r.bottle);
    t.grasp_plan_ms.insert(t.grasp_plan_ms.end(), r.grasp_plan_ms.begin(), r.grasp_plan_ms.end());
    t.grasp_plan_cpu_ms.insert(t.grasp_plan_cpu_ms.end(), r.grasp_plan_cpu_ms.begin(), r.grasp_plan_cpu_ms.end());
    for (const auto& [stage, ms] : r.grasp_plan_stages_ms) add_stage_times(t.grasp_plan_stages_ms, stage, ms);
  }
  t.objects_learned = static_cast<int>(learned.size());
  for (const Judged& j : judged) {
    t.good += j.good;
    t.bad += j.bad;
    t.distances_m.insert(t.distances_m.end(), j.distances_m.begin(), j.distances_m.end());
    if (j.target.empty()) {
      ++t.unknown_images;
      t.false_recognitions += !j.label.empty();
      continue;
    }
    ++t.test_images;
    const bool ok = !j.label.empty() && j.bottle == j.target;
    t.correct += ok;
    t.wrong += !j.label.empty() && !ok;
    t.unrecognised += j.label.empty();
    if (learned.count(j.target)) {
      ++t.test_images_of_learned;
      t.correct_of_learned += ok;
    }
  }
  return t;
}

std::string json_report(const Options& o, const std::vector<Run>& runs, const std::vector<Judged>& judged,
                        const Totals& t, const RecognitionTiming& timing, int padded_descriptors) {
  JsonWriter j;  // 6 significant digits
  j.begin_object();
  j.field("machine", machine_description()).field("date", today()).field("load_average_after_timing", load_average());
  j.field("objects_learned", t.objects_learned).field("objects", static_cast<int>(runs.size()));
  j.field("test_images", t.test_images).field("correct", t.correct).field("wrong", t.wrong).field("unrecognised", t.unrecognised);
  j.field("test_images_of_learned_objects", t.test_images_of_learned).field("correct_of_learned_objects", t.correct_of_learned);
  j.field("good_matches", t.good).field("bad_matches", t.bad).field("match_tolerance_mm", o.tolerance_mm);
  j.field("median_match_distance_mm", t.distances_m.empty() ? -1.0 : 1e3 * median(t.distances_m));
  j.field("unknown_images", t.unknown_images).field("false_recognitions", t.false_recognitions);
  j.field("training_scenes_checked", static_cast<int>(t.training_scenes.size()))
      .field("training_scenes_taken_for_another_object", t.training_scenes_taken);
  j.key("grasp_plan_ms").begin_object().field("median", t.grasp_plan_ms.empty() ? -1.0 : median(t.grasp_plan_ms))
      .field("max", t.grasp_plan_ms.empty() ? -1.0 : max_of(t.grasp_plan_ms)).field("grasps", static_cast<int>(t.grasp_plan_ms.size()))
      .field("cpu_median", t.grasp_plan_cpu_ms.empty() ? -1.0 : median(t.grasp_plan_cpu_ms))
      .field("cpu_max", t.grasp_plan_cpu_ms.empty() ? -1.0 : max_of(t.grasp_plan_cpu_ms))
      .field("thesis", 160).field("target", 50).end_object();
  j.key("grasp_plan_stages_median_ms").begin_object();
  for (const auto& [stage, ms] : t.grasp_plan_stages_ms) j.field(stage, median(ms));
  j.end_object();
  j.field("recognition_ms_at_100_objects", timing.median_ms).field("recognition_cpu_ms_at_100_objects", timing.median_cpu_ms);
  j.field("recognition_at_100_objects_matcher", timing.matcher).field("recognition_at_100_objects_descriptors", padded_descriptors);
  j.field("recognition_at_100_objects_answer", timing.label);
  int thesis_good = 0, thesis_bad = 0;
  for (const ThesisRow& r : kThesisTable) {
    thesis_good += r.good;
    thesis_bad += r.bad;
  }
  j.key("thesis").begin_object().field("objects_learned", 7).field("test_images", 28).field("correct", kThesisCorrect)
      .field("good_matches", thesis_good).field("bad_matches", thesis_bad).field("grasp_plan_ms", 160).end_object();
  j.key("objects").begin_array();
  for (const Run& r : runs) {
    int correct = 0, good = 0, bad = 0;
    for (const Judged& x : judged)
      if (x.target == r.bottle) {
        correct += !x.label.empty() && x.bottle == x.target;
        good += x.good;
        bad += x.bad;
      }
    j.begin_object().field("bottle", r.bottle).field("scene", r.scene).field("learned", !r.learned_name.empty())
        .field("learned_name", r.learned_name).field("why_not", r.why_not).field("attempts", r.attempts)
        .field("views", static_cast<int>(r.view_utimes.size())).field("run_wall_s", r.wall_s)
        .field("correct_of_4", correct).field("good_matches", good).field("bad_matches", bad);
    if (const ThesisRow* t = thesis_row(r.bottle)) j.field("thesis_good_matches", t->good).field("thesis_bad_matches", t->bad);
    j.end_object();
  }
  j.end_array();
  j.key("images").begin_array();
  for (const Judged& x : judged)
    j.begin_object().field("image", x.image).field("target", x.target).field("variant", x.variant).field("label", x.label)
        .field("recognised_as", x.bottle).field("reason", x.recognition.reason).field("verified_matches", x.verified)
        .field("best_view", x.best_view).field("good_matches", x.good).field("bad_matches", x.bad)
        .field("most_ratio_matches", x.most_ratio_matches).field("most_verified_matches", x.most_verified).end_object();
  j.end_array();
  j.end_object();
  return j.str() + "\n";
}

// " (brown_bottle as white_bottle, 5)" for the training scenes taken for another object; "" if none.
std::string taken_list(const std::vector<SceneCheck>& checks) {
  std::string out;
  for (const SceneCheck& c : checks)
    if (!c.taken_for.empty()) out += (out.empty() ? " (" : "; ") + c.bottle + " as " + c.taken_for + ", " + std::to_string(c.verified);
  return out.empty() ? out : out + " verified)";
}

std::string markdown_report(const Options& o, const std::vector<Run>& runs, const std::vector<Judged>& judged,
                            const Totals& t, const RecognitionTiming& timing, int padded_objects,
                            const std::string& sheet_of, const std::vector<std::string>& match_pictures,
                            const std::map<std::string, TrainingTruth>& training, cv::Size test_size) {
  std::ostringstream md;
  md << "# Object learning by interaction (thesis sec. 7.4, Table 7.1)\n\n"
     << "`experiments/learning.sh`: each of the seven bottles of `experiments/scenes/learning/` learned in simulation by "
        "one run of the whole chain (survey, nudge, segment, grasp, rotate, learn, place; `nudge_run_loop` with "
        "`NUDGE_LOOP_LEARN=1`, `--learn on`), all into one object database, no retries; then `nudge-exp-learning` "
        "recognises the 28 test images (4 per bottle) and the 10 images of objects never learned "
        "(`nudge-exp-learning-scenes --set eval`, seeds fixed in advance: `learning_scenes.md`) with the learner's "
        "`Recognizer` (ratio "
     << o.recognize.ratio << ", >= " << o.recognize.min_matches << " verified matches, RANSAC check"
     << (o.recognize.keypoint_agreement.on ? " with keypoint agreement" : " on places only")
     << (o.recognize.colour_tolerance > 0 ? ", ratio test by colour within " + std::to_string(o.recognize.colour_tolerance).substr(0, 5) : "")
     << ", SIFT contrast threshold "
     << o.recognize.sift.contrast_threshold << ", " << timing.matcher << "). The test images are the right camera's "
     << test_size.width << "x" << test_size.height << (test_size.width > 640 ? " high-resolution stills (as the robot "
        "takes them to look closely and learn; the 640x480 video frames of the same scenes show the bottles at a third "
        "of the training views' scale, docs/learning.md)" : " video frames") << ". "
     << (o.relearn ? "Every object relearned from its stored views with today's learning (`--relearn`; simulated axis tilts: " +
                         (o.learn.axis_tilts.empty() ? std::string("none") : learning::axis_tilts_text(o.learn.axis_tilts)) + ")"
                   : std::string("The database as the runs stored it"))
     << "; features learned at simulated tilts, where the models have any, matched "
     << (o.recognize.tilts_as_fallback ? "only when the views as taken recognise nothing" : "with the others, in one pass")
     << ".\n\n"
     << machine_description() << ", " << today() << ".\n\n"
     << "| | here | thesis |\n|---|---|---|\n"
     << "| objects learned | " << t.objects_learned << " of " << runs.size() << " | 7 of 7 |\n"
     << "| test images recognised correctly | " << t.correct << " of " << t.test_images << " (" << t.wrong << " wrong, "
     << t.unrecognised << " unrecognised) | 28 of 28 |\n"
     << "| ... of the learned bottles' images | " << t.correct_of_learned << " of " << t.test_images_of_learned << " | |\n"
     << "| good / bad matches (verified, tolerance " << o.tolerance_mm << " mm) | " << t.good << " / " << t.bad
     << " | 298 / 7 (judged by eye) |\n"
     << "| false recognitions on " << t.unknown_images << " never-learned objects | " << t.false_recognitions << " | 0 |\n"
     << "| training scenes (before stills) taken for another learned object | " << t.training_scenes_taken << " of "
     << t.training_scenes.size() << taken_list(t.training_scenes) << " | |\n"
     << "| grasp plan time, median / max of " << t.grasp_plan_ms.size() << " grasps | "
     << (t.grasp_plan_ms.empty() ? std::string("none") : fixed(median(t.grasp_plan_ms)) + " / " + fixed(max_of(t.grasp_plan_ms)) + " ms")
     << (t.grasp_plan_cpu_ms.empty() ? std::string()
                                     : " wall (the supervisor thread's CPU: " + fixed(median(t.grasp_plan_cpu_ms)) + " / " +
                                           fixed(max_of(t.grasp_plan_cpu_ms)) + " ms)")
     << " | 160 ms |\n"
     << "| recognition at " << padded_objects << " objects (one test image, SIFT included) | " << fixed(timing.median_ms, 0)
     << " ms wall, " << fixed(timing.median_cpu_ms, 0) << " ms CPU | |\n\n"
     << "## Table 7.1 in simulation\n\n"
     << "| bottle | learned? | correct of 4 | good matches | bad matches | thesis: correct, good / bad |\n|---|---|---|---|---|---|\n";
  for (const Run& r : runs) {
    int correct = 0, good = 0, bad = 0;
    for (const Judged& x : judged)
      if (x.target == r.bottle) {
        correct += !x.label.empty() && x.bottle == x.target;
        good += x.good;
        bad += x.bad;
      }
    md << "| " << r.bottle << " | " << (r.learned_name.empty() ? "no: " + r.why_not : "yes (" + std::to_string(r.view_utimes.size()) + " views)")
       << " | " << correct << " | " << good << " | " << bad << " | ";
    if (const ThesisRow* t = thesis_row(r.bottle)) md << "4, " << t->good << " / " << t->bad;
    md << " |\n";
  }
  md << "\n## Every image\n\n| image | recognised as | verified matches | good | bad | most ratio-test / verified matches of any object | label pixels in sight |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (const Judged& x : judged)
    md << "| " << x.image << " | " << (x.label.empty() ? "nothing (" + x.recognition.reason + ")" : x.bottle) << " | "
       << x.verified << " | " << x.good << " | " << x.bad << " | " << x.most_ratio_matches << " / " << x.most_verified << " | "
       << (x.label_pixels < 0 ? std::string("–") : std::to_string(x.label_pixels)) << " |\n";
  md << "\n`label pixels in sight`: the target's pixels in the test image whose height on the bottle lies in its "
        "label's band (the bodies are plain: the labels carry nearly all of the bottles' SIFT features), from the "
        "simulator's surface render of the image.\n";
  md << "\n**Good and bad matches.** A verified match (the recognised object's best training view, after the RANSAC "
        "check) is good when the test image's keypoint and the training view's keypoint show the same surface point "
        "of the same object: both within one pixel of that object's pixels, their object-frame coordinates within "
        << o.tolerance_mm << " mm (about three pixel footprints of a 640x480 image, six of a 1280x960 still, at the bottles' distance). "
        "The test side's coordinates were rendered with the test image (`World::render_surface`). The training side's "
        "are rendered again from the run's LCM log: the camera service drew each view as `render_snapshot(right)` "
        "after `apply_poses` of the `SIM_STATE` with the view's utime, and the same calls on the same scene give "
        "`render_snapshot_surface` of exactly that view.";
  std::vector<double> diffs;
  for (const auto& [name, tt] : training) diffs.insert(diffs.end(), tt.colour_difference.begin(), tt.colour_difference.end());
  if (!diffs.empty())
    md << " Check: the re-rendered colour views differ from the stored training views by " << fixed(median(diffs), 2)
       << " grey levels on average (median over " << diffs.size() << " views; max " << fixed(max_of(diffs), 2) << ").";
  md << "\n\n**Grasp plan time**: wall time from the after-nudge stills to the grasp command in the supervisor (both "
        "cameras' motion segmentations, the object's top, the grasp and the arm's plan), as each run's "
        "`attempt.json` records it (`learning.grasp_plan_ms`), on a machine shared with other jobs.\n\n";
  if (!t.grasp_plan_stages_ms.empty()) {
    md << "By stage (`learning.grasp_plan_stages_ms`; the CPU time of the thread each ran on, the wait for the "
          "left camera's thread in wall time), median over the grasps:\n\n| stage | ms |\n|---|---|\n";
    for (const auto& [stage, ms] : t.grasp_plan_stages_ms) md << "| " << stage << " | " << fixed(median(ms)) << " |\n";
    md << "\n";
  }
  md << "**Recognition at " << padded_objects << " objects**: the learned objects padded with synthetic textured "
        "objects of 12 views (`synthetic::object_models`, seeds " << kStandInSeed << "+), the first cluttered test "
        "image recognised " << timing.runs << " times (median; SIFT of the image included; load average " << load_average()
     << " afterwards). Answer: " << (timing.label.empty() ? "nothing" : timing.label) << ".\n\n";
  if (!sheet_of.empty())
    md << "## The training views of " << sheet_of << "\n\n![training views](" << o.name << "_views.png)\n\n";
  if (!match_pictures.empty()) {
    md << "## Match pictures (fig. 7.10)\n\nThe test image above, the best training view below, verified matches in red.\n\n";
    for (const std::string& p : match_pictures) md << "![" << p << "](" << p << ")\n\n";
  }
  return md.str();
}

// Up to three correct recognitions (one per variant), the hardest variants first, drawn by the library (fig. 7.10).
std::vector<std::string> write_match_pictures(const Options& o, const std::vector<Judged>& judged,
                                              const std::vector<TestImage>& images, const learning::ObjectDatabase& db,
                                              const learning::Recognizer& recognizer) {
  std::vector<std::string> written;
  for (const char* variant : {"occluded", "cluttered", "orientation", "plain"}) {
    for (size_t i = 0; i < judged.size(); ++i) {
      const Judged& x = judged[i];
      if (x.variant != variant || x.label.empty() || x.bottle != x.target) continue;
      const cv::Mat& held = recognizer.find(x.label)->views[x.best_view].image;
      const cv::Mat training = held.empty() ? db.load_view_image(x.label, x.best_view) : held;
      const cv::Mat picture = learning::draw_match_picture(images[i].colour, training,
                                                           recognizer.find(x.label)->views[x.best_view].features, x.recognition);
      const std::string file = o.name + "_match_" + variant + ".png";
      write_png(file, at_most_wide(picture, 800));
      written.push_back(file);
      break;
    }
    if (written.size() == 3) break;
  }
  return written;
}

int run(const Options& o) {
  std::vector<fs::path> scene_files;
  for (const auto& e : fs::directory_iterator(o.scenes))
    if (e.path().extension() == ".yaml" && e.path().filename().string().rfind("train", 0) == 0) scene_files.push_back(e.path());
  std::sort(scene_files.begin(), scene_files.end());
  if (scene_files.empty()) throw std::runtime_error(o.scenes + ": no train*.yaml scenes");
  std::vector<Run> runs;
  std::map<std::string, sim::ObjectSpec> bottles;
  for (const fs::path& f : scene_files) {
    runs.push_back(read_run(o.runs, f));
    bottles[runs.back().bottle] = runs.back().bottle_spec;
  }

  const learning::ObjectDatabase db(o.runs + "/objects");
  learning::LoadReport loaded = db.load_all(o.relearn);
  for (const std::string& e : loaded.errors) std::cerr << "nudge-exp-learning: database: " << e << "\n";
  if (o.relearn)
    for (auto& m : loaded.models) m = relearned(*m, o.learn, o.runs, o.table_view, o.view_mask, o.drop_standing_view);
  learning::Recognizer recognizer(o.recognize);
  std::map<std::string, std::string> bottle_of;  // learned name -> bottle
  std::map<std::string, TrainingTruth> training;
  for (const auto& m : loaded.models) {
    const auto run = std::find_if(runs.begin(), runs.end(), [&](const Run& r) { return r.learned_name == m->info.name; });
    if (run == runs.end()) throw std::runtime_error(db.root() + "/" + m->info.name + ": learned by no run's learning attempt");
    const bool extra_view = o.table_view && m->views.size() == run->view_utimes.size() + 1;  // --table-view's
    const bool dropped_view = o.drop_standing_view && m->views.size() + 1 == run->view_utimes.size();
    if (run->view_utimes.size() != m->views.size() && !extra_view && !dropped_view)
      throw std::runtime_error(db.root() + "/" + m->info.name + ": " + std::to_string(m->views.size()) + " views, the run sent " +
                               std::to_string(run->view_utimes.size()));
    recognizer.add(m);
    bottle_of[m->info.name] = run->bottle;
    training[m->info.name] = render_training_views(*run, scene_files[run - runs.begin()], db);
    std::cerr << "learned " << run->bottle << " as " << m->info.name << " (" << m->descriptor_count() << " descriptors)\n";
  }

  const std::vector<TestImage> images = read_test_images(o.test_images, o.set);
  if (images.empty()) throw std::runtime_error(o.test_images + "/manifest.json: no test images");
  std::vector<Judged> judged;
  nudge::Progress progress("nudge-exp-learning", static_cast<int>(images.size()));
  for (const TestImage& t : images) {
    progress.step(t.name);
    judged.push_back(recognise_and_judge(recognizer, t, bottles, bottle_of, training, o.tolerance_mm / 1e3));
    const Judged& x = judged.back();
    progress.note(x.image + ": " + (x.label.empty() ? "nothing (" + x.recognition.reason + ")" : x.bottle) + ", " +
                  std::to_string(x.good) + " good / " + std::to_string(x.bad) + " bad");
  }
  progress.clear_status();
  Totals totals = add_up(runs, judged);
  totals.training_scenes = check_training_scenes(recognizer, runs, loaded.models, bottle_of);
  for (const SceneCheck& c : totals.training_scenes) {
    totals.training_scenes_taken += !c.taken_for.empty();
    if (!c.taken_for.empty())
      std::cerr << "training scene of the " << c.bottle << " taken for the " << c.taken_for << " (" << c.verified << " verified matches)\n";
  }

  std::vector<std::shared_ptr<const learning::ObjectModel>> padded = loaded.models;
  for (auto& stand_in : learning::synthetic::object_models("stand_in_", kPaddedObjects - static_cast<int>(padded.size()), kStandInSeed))
    padded.push_back(stand_in);
  int descriptors = 0;
  for (const auto& m : padded) descriptors += m->descriptor_count();
  const auto cluttered = std::find_if(images.begin(), images.end(), [](const TestImage& t) { return t.variant == TestVariant::Cluttered; });
  const RecognitionTiming timing = time_recognition(padded, (cluttered == images.end() ? images.front() : *cluttered).colour,
                                                    learning::RecognizeParams{}.matcher, kTimingRuns);

  std::string sheet_of;
  if (!loaded.models.empty()) {
    const auto most = std::max_element(loaded.models.begin(), loaded.models.end(),
                                       [](const auto& a, const auto& b) { return a->views.size() < b->views.size(); });
    write_png(o.name + "_views.png", views_sheet(db, **most));
    sheet_of = bottle_of.at((*most)->info.name) + " (" + (*most)->info.name + ")\n\nAs learned: the box (green) and the "
               "descriptors kept after pruning (red).";
  } else {
    const auto most = std::max_element(runs.begin(), runs.end(), [](const Run& a, const Run& b) { return a.most_views_count < b.most_views_count; });
    const cv::Mat sheet = taken_views_sheet(*most);
    if (!sheet.empty()) {
      write_png(o.name + "_views.png", sheet);
      sheet_of = most->bottle + " (not learned)\n\nNo object was learned: the " + std::to_string(most->most_views_count) +
                 " views its run took before the attempt ended (" + most->why_not + "), as the supervisor saved them.";
    }
  }
  const std::vector<std::string> pictures = write_match_pictures(o, judged, images, db, recognizer);
  write_result(o.name + ".json", json_report(o, runs, judged, totals, timing, descriptors));
  write_result(o.name + ".md", markdown_report(o, runs, judged, totals, timing, static_cast<int>(padded.size()), sheet_of,
                                               pictures, training, images.front().colour.size()));
  progress.finish(std::to_string(totals.objects_learned) + " objects learned, " + std::to_string(totals.correct) + " of " +
                  std::to_string(totals.test_images) + " test images recognised, " +
                  std::to_string(totals.false_recognitions) + " false recognitions");
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  Flags flags("nudge-exp-learning", "Score the object-learning experiment's runs (thesis Table 7.1).");
  flags.add_string("runs", &o.runs, "experiments/learning.sh's runs folder (one folder per scene, objects/ the database)");
  flags.add_string("scenes", &o.scenes, "the training scenes' folder (train*.yaml)");
  flags.add_string("test-images", &o.test_images, "nudge-exp-learning-scenes --set eval's output folder");
  flags.add_double("tolerance-mm", &o.tolerance_mm, "a good match's two surface points lie within this distance, mm");
  flags.add_string("name", &o.name, "result name (docs/results/NAME.*)");
  flags.add_string("set", &o.set, "the test images' set: eval (reported) or dev (tuning; nudge-exp-learning-scenes --set dev)");
  flags.add_bool("relearn", &o.relearn, "learn every stored object again from its stored views with today's learning");
  flags.add_bool("table-view", &o.table_view,
                 "--relearn, runs recorded without the supervisor's standing view: the attempt's after still as one more "
                 "view (its mask's box), pruned against the before still (its matches are not judged)");
  flags.add_bool("drop-standing-view", &o.drop_standing_view,
                 "--relearn, runs recorded with the supervisor's standing view: learn without it, as the learner would have");
  std::string view_mask = o.view_mask ? "on" : "off";
  flags.add_string("view-mask", &view_mask,
                   "--relearn, on|off: the standing or table view keeps only the keypoints inside the right segmentation");
  flags.add_double("mask-support", &o.learn.mask_support,
                   "--relearn: a masked view's keypoint is kept when its disc, this many times SIFT's radius, lies inside (0: centre)");
  std::string axis_tilts = learning::axis_tilts_text(o.learn.axis_tilts);
  flags.add_string("axis-tilts", &axis_tilts, "--relearn: simulated tilts along the held object's axis, comma-separated (\"\": none)");
  flags.add_int("background-matches", &o.learn.background_matches, "--relearn: other views a background descriptor matches");
  flags.add_double("background-static-px", &o.learn.background_static_px,
                   "--relearn: a match counts towards background only within this many pixels (0: anywhere)");
  std::string affine = o.recognize.affine_check ? "on" : "off";
  flags.add_string("affine-check", &affine, "on|off: the geometric check also tries an affine map (foreshortening)");
  flags.add_double("ratio", &o.recognize.ratio, "Lowe's ratio in recognition");
  std::string agreement = o.recognize.keypoint_agreement.on ? "on" : "off";
  flags.add_string("keypoint-agreement", &agreement,
                   "on|off: a verified match's keypoints must also agree with the mapping's turn and scale");
  flags.add_double("agreement-angle", &o.recognize.keypoint_agreement.angle_deg, "--keypoint-agreement: degrees");
  flags.add_double("agreement-scale", &o.recognize.keypoint_agreement.scale_factor, "--keypoint-agreement: factor");
  flags.add_double("colour-tolerance", &o.recognize.colour_tolerance,
                   "the ratio test by colour: chromaticity distance a candidate may be off the query keypoint's; 0 off");
  flags.add_double("ransac-px", &o.recognize.ransac_px, "the geometric check's inlier distance, pixels");
  flags.add_double("distinct-place-px", &o.recognize.distinct_place_px,
                   "matches whose training keypoints lie within this many pixels are one place of the label (0: each match one)");
  flags.add_int("min-support", &o.recognize.min_support, "matches agreeing with a mapping beyond those that fixed it");
  std::string root_sift = o.recognize.root_sift ? "on" : "off";
  flags.add_string("root-sift", &root_sift, "on|off: match RootSIFT descriptors (Hellinger distance)");
  std::string tilts_as_fallback = o.recognize.tilts_as_fallback ? "on" : "off";
  flags.add_string("tilts-as-fallback", &tilts_as_fallback,
                   "on|off: the simulated tilts' features matched only when the views as taken recognise nothing");
  flags.add_double("sift-contrast", &o.recognize.sift.contrast_threshold,
                   "SIFT's contrast threshold in recognition and, with --relearn, in learning");
  flags.add_double("sift-equalise", &o.recognize.sift.equalise_clip,
                   "CLAHE clip limit before SIFT in recognition and, with --relearn, in learning (0: none)");
  flags.add_int("sift-equalise-tile", &o.recognize.sift.equalise_tile_px, "CLAHE's tile size, pixels");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (affine != "on" && affine != "off") throw FlagError("--affine-check must be on or off");
    if (view_mask != "on" && view_mask != "off") throw FlagError("--view-mask must be on or off");
    o.view_mask = view_mask == "on";
    if (!(o.learn.mask_support >= 0)) throw FlagError("--mask-support must be >= 0");
    o.recognize.affine_check = affine == "on";
    if (agreement != "on" && agreement != "off") throw FlagError("--keypoint-agreement must be on or off");
    o.recognize.keypoint_agreement.on = agreement == "on";
    if (root_sift != "on" && root_sift != "off") throw FlagError("--root-sift must be on or off");
    o.recognize.root_sift = root_sift == "on";
    if (tilts_as_fallback != "on" && tilts_as_fallback != "off") throw FlagError("--tilts-as-fallback must be on or off");
    o.recognize.tilts_as_fallback = tilts_as_fallback == "on";
    try {
      o.learn.axis_tilts = learning::axis_tilts_from_text(axis_tilts);
    } catch (const std::invalid_argument& e) {
      throw FlagError(std::string("--axis-tilts: ") + e.what());
    }
    o.learn.sift = o.recognize.sift;  // as the learner: both find the same keypoints
    // (the learner's own ratio between views stays LearnParams' 0.6, as nudge-learner's does)
    if (o.runs.empty() || o.scenes.empty() || o.test_images.empty()) throw FlagError("--runs, --scenes and --test-images are required");
    if (!(o.tolerance_mm > 0)) throw FlagError("--tolerance-mm must be positive");
    return run(o);
  } catch (const FlagError& e) {
    std::cerr << "nudge-exp-learning: " << e.what() << "\n" << flags.help();
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-learning: " << e.what() << "\n";
    return 1;
  }
}
