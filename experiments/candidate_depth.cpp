// How far each real survey candidate of recorded loop runs stands from its object, and how far the
// object's lines found again in the survey's own camera frames would place it. The push runs
// across the right camera's view, so the error along that camera's ray decides whether the pad
// meets the object or a neighbour. For each survey (CANDIDATES) of each run
// (experiments/nudge_segmentation.sh's RUNS_DIR/<scene>/<scene>/<scene>.lcmlog), each candidate
// within --real-radius of an upright object (the simulator's SIM_STATE then) is compared with:
//   - the lines re-found near its projected axis in the stereo pair taken just before the survey
//     answered (find_line_near, the supervisor's still search), within each window of --windows
//     (px at 640x480 either side of the projected axis), triangulated and met with the table; and
//     the same place kept only when it lies within --max-move of the candidate.
//   nudge-exp-candidate-depth RUNS_DIR [RUNS_DIR...] [--real-radius 0.05] [--windows 10,15,30]
//                             [--max-move 0.05] [--name STEM]
// Writes docs/results/STEM.{json,md} (default candidate_depth). Choose on development runs only.
#include <algorithm>
#include <cmath>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "nudge/bus/image.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/geometry/plane.hpp"
#include "nudge/geometry/triangulation.hpp"
#include "nudge/image_t.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor/line_search.hpp"
#include "nudge/supervisor/scene.hpp"
#include "report.hpp"
#include "run_logs.hpp"

namespace fs = std::filesystem;
namespace sv = nudge::supervisor;
namespace geo = nudge::geometry;
using nudge::experiments::latest_at;
using nudge::experiments::median;
using nudge::experiments::parse_list;
using nudge::experiments::read_channel;
using nudge::experiments::state_at;

namespace {

constexpr double kAxisHeight = 0.1;  // the predicted axis' length above the table, m

// A candidate's place error: along the right camera's horizontal ray and in all, m.
struct PlaceError {
  double along = 0, total = 0;
};

PlaceError place_error(const Eigen::Vector3d& place, const Eigen::Vector3d& truth, const Eigen::Vector3d& camera) {
  const Eigen::Vector2d ray = (place - camera).head<2>().normalized();
  const Eigen::Vector2d off = (truth - place).head<2>();
  return {off.dot(ray), off.norm()};
}

// Where the object's lines, found again near the candidate's projected axis in both images, put it
// on the table (world); nothing when a camera shows no line or the two do not meet on the table.
std::optional<Eigen::Vector3d> refound_place(const sv::SceneGeometry& scene, const cv::Mat& left, const cv::Mat& right,
                                             const Eigen::Vector3d& candidate, const sv::LineSearchParams& params) {
  const auto predicted_left = scene.left_axis_line(candidate, kAxisHeight, left.size());
  const auto predicted_right = scene.right_axis_line(candidate, kAxisHeight, right.size());
  if (!predicted_left || !predicted_right) return std::nullopt;
  const auto left_line = sv::find_line_near(left, *predicted_left, params);
  const auto right_line = sv::find_line_near(right, *predicted_right, params);
  if (!left_line || !right_line) return std::nullopt;
  const auto axis = geo::triangulate_axis(scene.rig(), *left_line, *right_line);
  if (!axis) return std::nullopt;
  const auto hit = geo::check_axis(*axis, scene.table());
  if (!hit) return std::nullopt;
  return scene.right_to_world(hit->point);
}

struct Row {
  std::string run, object;
  int survey = 0;
  PlaceError candidate;
  std::vector<std::optional<PlaceError>> refound;  // per window
  std::vector<double> moved;                         // per window: how far from the candidate, m (NAN: none)
};

std::string mm(const std::optional<PlaceError>& e) {
  if (!e) return "–";
  return std::to_string(std::lround(1000 * e->along)) + " / " + std::to_string(std::lround(1000 * e->total));
}

// A summary of one way of placing: candidates placed, the median |error| along the ray, and how
// many within 15 mm and beyond 40 mm along it.
struct Summary {
  int placed = 0, within_15mm = 0, beyond_40mm = 0;
  double median_along = NAN;
};

Summary summarise(const std::vector<std::optional<PlaceError>>& errors) {
  Summary s;
  std::vector<double> along;
  for (const auto& e : errors) {
    if (!e) continue;
    ++s.placed;
    along.push_back(std::fabs(e->along));
    s.within_15mm += std::fabs(e->along) <= 0.015;
    s.beyond_40mm += std::fabs(e->along) > 0.040;
  }
  s.median_along = median(along);
  return s;
}

}  // namespace

int main(int argc, char** argv) try {
  std::vector<std::string> run_sets;
  double real_radius = 0.05, max_move = 0.05;
  std::vector<double> windows{10, 15, 30};
  std::string name = "candidate_depth";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--real-radius" && has_value) real_radius = std::stod(argv[++i]);
    else if (arg == "--windows" && has_value) windows = parse_list(argv[++i], arg);
    else if (arg == "--max-move" && has_value) max_move = std::stod(argv[++i]);
    else if (arg == "--name" && has_value) name = argv[++i];
    else if (!arg.empty() && arg[0] != '-') run_sets.push_back(arg);
    else throw std::invalid_argument("unknown option " + arg +
                                     " (RUNS_DIR... [--real-radius 0.05] [--windows 10,15,30] [--max-move 0.05] [--name STEM])");
  }
  if (run_sets.empty()) throw std::invalid_argument("give at least one RUNS_DIR");
  const fs::path source = NUDGE_SOURCE_DIR;
  const sv::SceneGeometry scene = sv::SceneGeometry::load((source / "config/calibration_sim.yaml").string());
  const Eigen::Vector3d camera = scene.right_camera_in_world();

  std::vector<Row> rows;
  const auto logs = nudge::experiments::run_logs(run_sets);
  nudge::Progress progress("nudge-exp-candidate-depth", static_cast<int>(logs.size()));
  for (const auto& [run, log] : logs) {
    progress.step(run);
    const auto states = read_channel<nudge::sim_state_t>(log, "SIM_STATE");
    const auto lefts = read_channel<nudge::image_t>(log, "CAMERA_LEFT");
    const auto rights = read_channel<nudge::image_t>(log, "CAMERA_RIGHT");
    int survey_number = 0;
    for (const auto& survey : read_channel<nudge::candidates_t>(log, "CANDIDATES")) {
      ++survey_number;
      const nudge::sim_state_t* state = state_at(states, survey.utime);
      const nudge::image_t* left = latest_at(lefts, survey.utime);
      const nudge::image_t* right = left ? latest_at(rights, left->utime) : nullptr;
      if (!state || !right || right->utime != left->utime) continue;
      const cv::Mat left_image = nudge::bus::to_mat(*left), right_image = nudge::bus::to_mat(*right);
      for (int i = 0; i < survey.num_candidates; ++i) {
        const Eigen::Vector3d place =
            scene.table_to_world({survey.position[i][0], survey.position[i][1], survey.position[i][2]});
        const nudge::object_state_t* object = nullptr;
        double nearest = real_radius;
        for (const auto& o : state->objects) {
          const double d = std::hypot(o.pose.position[0] - place.x(), o.pose.position[1] - place.y());
          if (d <= nearest) nearest = d, object = &o;
        }
        if (!object) continue;
        const Eigen::Vector3d truth(object->pose.position[0], object->pose.position[1], 0);
        Row row{run, object->name, survey_number, place_error(place, truth, camera), {}, {}};
        for (const double window : windows) {
          sv::LineSearchParams params;
          params.window_px = window;  // at 640x480: the survey's frames
          const auto p = refound_place(scene, left_image, right_image, place, params);
          row.refound.push_back(p ? std::optional<PlaceError>(place_error(*p, truth, camera)) : std::nullopt);
          row.moved.push_back(p ? (*p - place).head<2>().norm() : NAN);
        }
        rows.push_back(row);
      }
    }
    progress.note(run + ": " + std::to_string(rows.size()) + " real candidates so far");
  }
  progress.finish(std::to_string(rows.size()) + " real candidates of " + std::to_string(logs.size()) + " runs");

  std::ostringstream md;
  md << "# Candidates' depth along the right camera's ray: surveyed, and the lines found again\n\n"
     << "`nudge-exp-candidate-depth` took every real survey candidate (within " << real_radius * 1000
     << " mm of an object) of the recorded runs and compared its place with the object's: along the right "
        "camera's horizontal ray (the push runs across it) and in all. The object's lines were then found again near "
        "the candidate's projected axis in the stereo pair taken just before the survey answered (`find_line_near`, "
        "the supervisor's still search, the strongest line within the window either side of the projection and 6 deg), "
        "triangulated and met with the table; `kept within "
     << max_move * 1000 << " mm`: that place only when it lies so near the candidate, else the candidate's. Runs: ";
  for (size_t i = 0; i < run_sets.size(); ++i) md << (i ? ", " : "") << i + 1 << ": `" << run_sets[i] << "`";
  md << ". " << nudge::experiments::machine_description() << ", " << nudge::experiments::today() << ".\n\n"
     << "| place from | candidates placed | median error along the ray (mm) | within 15 mm | beyond 40 mm |\n|---|---|---|---|---|\n";
  nudge::JsonWriter json(4);
  json.begin_object().field("machine", nudge::experiments::machine_description()).field("date", nudge::experiments::today());
  json.field("max_move_m", max_move).key("places").begin_array();
  auto report = [&](const std::string& label, const std::vector<std::optional<PlaceError>>& errors) {
    const Summary s = summarise(errors);
    md << "| " << label << " | " << s.placed << " | " << std::lround(1000 * s.median_along) << " | " << s.within_15mm
       << " | " << s.beyond_40mm << " |\n";
    json.begin_object().field("from", label).field("placed", s.placed).field("median_along_mm", 1000 * s.median_along);
    json.field("within_15mm", s.within_15mm).field("beyond_40mm", s.beyond_40mm).end_object();
  };
  std::vector<std::optional<PlaceError>> surveyed;
  for (const Row& r : rows) surveyed.push_back(r.candidate);
  report("the survey", surveyed);
  for (size_t w = 0; w < windows.size(); ++w) {
    std::vector<std::optional<PlaceError>> refound, kept;
    for (const Row& r : rows) {
      refound.push_back(r.refound[w]);
      kept.push_back(r.refound[w] && r.moved[w] <= max_move ? r.refound[w] : std::optional<PlaceError>(r.candidate));
    }
    const std::string window = std::to_string(std::lround(windows[w]));
    report("lines found again within " + window + " px", refound);
    report("... kept within " + std::to_string(std::lround(max_move * 1000)) + " mm (" + window + " px)", kept);
  }
  json.end_array().end_object();
  md << "\nPer candidate, error along the ray / in all (mm):\n\n| run | survey | object | the survey |";
  for (double w : windows) md << " found again within " << std::lround(w) << " px |";
  md << "\n|---|---|---|---|";
  for (size_t w = 0; w < windows.size(); ++w) md << "---|";
  md << "\n";
  for (const Row& r : rows) {
    md << "| " << r.run << " | " << r.survey << " | " << r.object << " | " << mm(r.candidate) << " |";
    for (const auto& e : r.refound) md << " " << mm(e) << " |";
    md << "\n";
  }
  nudge::experiments::write_result(name + ".json", json.str() + "\n");
  nudge::experiments::write_result(name + ".md", md.str());
  return 0;
} catch (const std::exception& e) {
  std::cerr << "nudge-exp-candidate-depth: " << e.what() << "\n";
  return 1;
}
