// Why objects of recorded runs were not candidates. Every survey of every run (a CANDIDATES_REQUEST
// and the stereo pairs gathered before its CANDIDATES) is taken apart object by object: for each
// object standing on the table, not explored yet and not a candidate of that survey, its line (the
// simulator's image of its true axis, SIM_STATE) is looked for among each camera's symmetry lines
//   * as the run published them (SYMMETRY_LEFT/RIGHT, recorded), and
//   * as nudge-symmetry finds them on the same recorded camera frames when it cuts nothing after its
//     peaks (the run's own flags from its launch.json, then --reach-keep 0 --min-peak-ratio 0, or
//     --deep-flags; "none": no deep replay): the peaks the reach filter keeps, with their votes.
// Each such miss is put in the first class that holds (a camera "has" the line in at least a third
// of the survey's frames):
//   paired-but-dropped  published in both cameras: the survey's pairing or clustering lost it
//   cut-from-published  among the deep peaks in both cameras, not published in one (rank or the
//                       weak-peak cut, --min-peak-ratio, of the top line)
//   not-found           not among the deep peaks in one camera or both (occluded, weak edges, or
//                       out of the reach filter's ring)
// Writes docs/results/NAME.{json,md} (default survey_misses).
//   nudge-exp-survey-misses RUNS_DIR [RUNS_DIR...] [--deep-flags "..."] [--line-px 12] [--line-deg 3]
//                           [--real-radius 0.03] [--name STEM]
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "nudge/candidates_request_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor/scene.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "report.hpp"
#include "run_logs.hpp"

namespace fs = std::filesystem;
using nudge::experiments::read_channel;
using nudge::experiments::shell_quote;
using nudge::experiments::state_at;

namespace {

struct Tolerance {
  double px = 12;   // a mug's strongest line stands up to ~10 px off its axis' image (its handle)
  double deg = 3;
};

// One camera's lines in one frame, strongest first (votes as published).
using FrameLines = std::vector<nudge::symmetry_line_t>;
// camera channel -> image utime -> lines
using LinesByFrame = std::map<std::string, std::map<int64_t, FrameLines>>;

LinesByFrame lines_by_frame(const fs::path& log) {
  LinesByFrame lines;
  for (const std::string channel : {"SYMMETRY_LEFT", "SYMMETRY_RIGHT"})
    for (auto& m : read_channel<nudge::symmetry_lines_t>(log, channel)) lines[channel][m.utime] = std::move(m.lines);
  return lines;
}

// The rank (0: strongest) of the first line within tolerance of (r, theta), or -1.
int rank_of(const FrameLines& lines, double r, double theta, const Tolerance& tol) {
  for (size_t i = 0; i < lines.size(); ++i) {
    double dtheta = std::abs(lines[i].theta - theta);
    double dr = std::abs(lines[i].r - r);
    if (dtheta > M_PI / 2) dtheta = M_PI - dtheta, dr = std::abs(lines[i].r + r);  // the same line across +-90 deg
    if (dtheta <= tol.deg * M_PI / 180 && dr <= tol.px) return static_cast<int>(i);
  }
  return -1;
}

// One survey as the run made it: its request, its answer, and the image times of the stereo pairs
// it could have gathered (the right camera's lines published between the two).
struct Survey {
  nudge::candidates_request_t request;
  nudge::candidates_t answer;
  std::vector<int64_t> frames;
};

std::vector<Survey> surveys_of(const fs::path& log_path) {
  std::vector<Survey> surveys;
  lcm::LogFile log(log_path.string(), "r");
  if (!log.good()) throw std::runtime_error("cannot read " + log_path.string());
  bool open = false;
  Survey current;
  for (const lcm::LogEvent* e = log.readNextEvent(); e; e = log.readNextEvent()) {
    if (e->channel == "CANDIDATES_REQUEST" && current.request.decode(e->data, 0, e->datalen) >= 0) {
      open = true;
      current.frames.clear();
    } else if (open && e->channel == "SYMMETRY_RIGHT") {
      nudge::symmetry_lines_t m;
      if (m.decode(e->data, 0, e->datalen) >= 0 && m.utime >= current.request.utime) current.frames.push_back(m.utime);
    } else if (open && e->channel == "CANDIDATES" && current.answer.decode(e->data, 0, e->datalen) >= 0) {
      // The service gathers the first `frames` pairs after the request; later ones wait unused.
      const size_t gathered = current.answer.frames_used > 0 ? static_cast<size_t>(current.answer.frames_used) : current.frames.size();
      if (current.frames.size() > gathered) current.frames.resize(gathered);
      surveys.push_back(current);
      open = false;
    }
  }
  return surveys;
}

// The lines nudge-symmetry finds on the run's camera frames with its own flags and then `extra`.
LinesByFrame deep_lines(const fs::path& log, const std::string& extra, const fs::path& out) {
  nudge::experiments::replay_symmetry(log, extra, out);
  LinesByFrame lines = lines_by_frame(out);
  fs::remove(out);
  return lines;
}

// How one camera saw one object over a survey's frames.
struct Sighting {
  int published = 0;  // frames whose published lines hold it
  int deep = 0;       // frames whose deep peaks hold it
  std::vector<double> published_rank, deep_rank, vote_ratio;  // where found (vote ratio: to the top deep peak)
};

Sighting sight(const std::vector<int64_t>& frames, const std::map<int64_t, FrameLines>& published,
               const std::map<int64_t, FrameLines>& deep, double r, double theta, const Tolerance& tol) {
  Sighting s;
  for (int64_t t : frames) {
    if (auto it = published.find(t); it != published.end()) {
      const int k = rank_of(it->second, r, theta, tol);
      if (k >= 0) ++s.published, s.published_rank.push_back(k);
    }
    if (auto it = deep.find(t); it != deep.end() && !it->second.empty()) {
      const int k = rank_of(it->second, r, theta, tol);
      if (k >= 0) {
        ++s.deep;
        s.deep_rank.push_back(k);
        s.vote_ratio.push_back(it->second[k].votes / std::max(1.0f, it->second.front().votes));
      }
    }
  }
  return s;
}

struct Miss {
  std::string run, object, cls;
  int survey = 0, frames = 0;
  double base_distance = 0;
  Sighting left, right;
};

std::string sighting_text(const Sighting& s, int frames) {
  std::ostringstream t;
  t.precision(2);
  t << s.published << "/" << frames;
  if (!s.published_rank.empty()) t << " (rank " << nudge::experiments::median(s.published_rank) << ")";
  t << "; " << s.deep << "/" << frames;
  if (!s.deep_rank.empty())
    t << " (rank " << nudge::experiments::median(s.deep_rank) << ", votes " << nudge::experiments::median(s.vote_ratio)
      << " of the top)";
  return t.str();
}

}  // namespace

int main(int argc, char** argv) try {
  std::vector<std::string> run_sets;
  std::string deep_flags = "--reach-keep 0 --min-peak-ratio 0";
  Tolerance tol;
  double real_radius = 0.03;
  std::string name = "survey_misses";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--deep-flags" && has_value) deep_flags = argv[++i];
    else if (arg == "--line-px" && has_value) tol.px = std::stod(argv[++i]);
    else if (arg == "--line-deg" && has_value) tol.deg = std::stod(argv[++i]);
    else if (arg == "--real-radius" && has_value) real_radius = std::stod(argv[++i]);
    else if (arg == "--name" && has_value) name = argv[++i];
    else if (!arg.empty() && arg[0] == '-') throw std::invalid_argument("unknown option " + arg);
    else run_sets.push_back(arg);
  }
  if (run_sets.empty()) {
    std::cerr << "usage: nudge-exp-survey-misses RUNS_DIR [RUNS_DIR...] [--deep-flags \"...\"] [--line-px 12] "
                 "[--line-deg 3] [--real-radius 0.03] [--name STEM]\n";
    return 2;
  }
  const fs::path source = NUDGE_SOURCE_DIR;
  const auto scene = nudge::supervisor::SceneGeometry::load((source / "config/calibration_sim.yaml").string());
  const auto logs = nudge::experiments::run_logs(run_sets);
  const fs::path deep_log = fs::temp_directory_path() / ("survey_misses_" + std::to_string(getpid()) + ".lcmlog");

  std::vector<Miss> misses;
  int object_surveys = 0, candidates = 0, explored = 0;
  nudge::Progress progress("nudge-exp-survey-misses", static_cast<int>(logs.size()));
  for (const auto& [run, log] : logs) {
    progress.step(run);
    const auto states = read_channel<nudge::sim_state_t>(log, "SIM_STATE");
    if (states.empty()) throw std::runtime_error(log.string() + ": no SIM_STATE (a simulated run's log is needed)");
    const auto surveys = surveys_of(log);
    if (surveys.empty()) continue;
    const LinesByFrame published = lines_by_frame(log);
    const LinesByFrame deep = deep_flags == "none" ? LinesByFrame{} : deep_lines(log, deep_flags, deep_log);
    for (size_t k = 0; k < surveys.size(); ++k) {
      const Survey& survey = surveys[k];
      const nudge::sim_state_t* state = state_at(states, survey.request.utime);
      if (!state) continue;
      for (const auto& o : state->objects) {
        const Eigen::Vector2d at(o.pose.position[0], o.pose.position[1]);
        if (std::abs(o.axis_direction[2]) < std::cos(20 * M_PI / 180)) continue;  // lying: no upright axis to find
        ++object_surveys;
        auto near = [&](const double p[3]) {
          const Eigen::Vector3d w = scene.table_to_world({p[0], p[1], p[2]});
          return (w.head<2>() - at).norm() <= real_radius;
        };
        bool was_explored = false, was_candidate = false;
        for (const auto& e : survey.request.explored) was_explored = was_explored || near(e.data());
        for (const auto& c : survey.answer.position) was_candidate = was_candidate || near(c.data());
        if (was_explored) { ++explored; continue; }
        if (was_candidate) { ++candidates; continue; }
        Miss m;
        m.run = run;
        m.object = o.name;
        m.survey = static_cast<int>(k) + 1;
        m.frames = static_cast<int>(survey.frames.size());
        m.base_distance = at.norm();
        auto channel_lines = [](const LinesByFrame& l, const std::string& c) -> const std::map<int64_t, FrameLines>& {
          static const std::map<int64_t, FrameLines> none;
          auto it = l.find(c);
          return it == l.end() ? none : it->second;
        };
        m.left = sight(survey.frames, channel_lines(published, "SYMMETRY_LEFT"), channel_lines(deep, "SYMMETRY_LEFT"),
                       o.r_left, o.theta_left, tol);
        m.right = sight(survey.frames, channel_lines(published, "SYMMETRY_RIGHT"), channel_lines(deep, "SYMMETRY_RIGHT"),
                        o.r_right, o.theta_right, tol);
        const int third = std::max(1, m.frames / 3);
        if (m.left.published >= third && m.right.published >= third) m.cls = "paired-but-dropped";
        else if (m.left.deep >= third && m.right.deep >= third) m.cls = "cut-from-published";
        else m.cls = "not-found";
        misses.push_back(m);
      }
    }
    progress.note(run + ": " + std::to_string(surveys.size()) + " surveys");
  }
  progress.finish(std::to_string(logs.size()) + " runs");

  std::map<std::string, int> by_class;
  for (const auto& m : misses) ++by_class[m.cls];
  nudge::JsonWriter json(4);
  json.begin_object().field("machine", nudge::experiments::machine_description()).field("date", nudge::experiments::today());
  json.field("runs", static_cast<int>(logs.size())).field("deep_flags", deep_flags);
  json.field("objects_standing_over_surveys", object_surveys).field("candidates", candidates).field("explored", explored);
  json.field("missed", static_cast<int>(misses.size()));
  for (const char* c : {"paired-but-dropped", "cut-from-published", "not-found"}) json.field(c, by_class[c]);
  json.end_object();

  std::ostringstream md;
  md << "# Survey misses: where the lines of objects that were not candidates went\n\n"
     << "`nudge-exp-survey-misses` took every survey of each recorded run apart object by object. An upright object "
        "standing on the table, not explored yet, and not a candidate of the survey (no candidate within "
     << real_radius * 1000 << " mm) is a miss. Its line (the image of its true axis, within " << tol.px << " px and "
     << tol.deg << " deg) was looked for in each camera's lines over the survey's stereo pairs: as published, and among "
        "the peaks nudge-symmetry finds on the same recorded frames with the run's own flags and `" << deep_flags
     << "` (deep). A camera has the line when it is there in at least a third of the frames. Runs: ";
  for (size_t i = 0; i < run_sets.size(); ++i) md << (i ? ", " : "") << i + 1 << ": `" << run_sets[i] << "`";
  md << " (" << logs.size() << " runs). " << nudge::experiments::machine_description() << ", " << nudge::experiments::today()
     << ".\n\n| | object-surveys |\n|---|---|\n| upright objects standing, over all surveys | " << object_surveys
     << " |\n| a candidate | " << candidates << " |\n| explored (left out by design) | " << explored << " |\n| missed | "
     << misses.size() << " |\n| missed: published in both cameras (paired but dropped) | " << by_class["paired-but-dropped"]
     << " |\n| missed: a deep peak in both, not published in one (cut) | " << by_class["cut-from-published"]
     << " |\n| missed: not a deep peak in one camera or both | " << by_class["not-found"] << " |\n\n"
     << "Per miss (left and right: frames published (median rank); frames among the deep peaks (median rank, median votes "
        "as a fraction of the top peak's)):\n\n| run | survey | object | from the base (m) | class | left | right |\n|---|---|---|---|---|---|---|\n";
  for (const auto& m : misses) {
    md.precision(3);
    md << "| " << m.run << " | " << m.survey << " | " << m.object << " | " << m.base_distance << " | " << m.cls << " | "
       << sighting_text(m.left, m.frames) << " | " << sighting_text(m.right, m.frames) << " |\n";
  }
  nudge::experiments::write_result(name + ".json", json.str() + "\n");
  nudge::experiments::write_result(name + ".md", md.str());
  return 0;
} catch (const std::exception& e) {
  std::cerr << "nudge-exp-survey-misses: " << e.what() << "\n";
  return 1;
}
