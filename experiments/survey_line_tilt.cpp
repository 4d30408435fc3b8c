// The survey-line tilt (nudge-triangulation --candidate-line-tilt) chosen on recorded runs: each
// run's log (experiments/nudge_segmentation.sh's RUNS_DIR/<scene>/<scene>/<scene>.lcmlog) is
// replayed through nudge-triangulation at each tilt, with the run's own SYMMETRY lines and
// CANDIDATES_REQUESTs, and every candidate of every survey is scored against the simulator's
// SIM_STATE of that moment: within --real-radius of an object it is that object (real), else a
// phantom. With --lines, each CANDIDATES_REQUEST is also replayed asking for that many lines per
// image (the supervisor's --survey-lines) instead of the recorded number. With --published, each
// SYMMETRY message is also cut to its first N lines (the symmetry service's --reach-keep: runs
// recorded with more lines published replayed as if fewer had been). With --column, the surveys
// treat the arm base column's lines as each mode says (nudge-triangulation
// --candidate-column-lines: counted, dropped, uncounted). With --published-column-uncounted, each
// --published N is also replayed with the column's lines riding along uncounted among the N
// (nudge-symmetry --reach-column-px 8). With --symmetry, the run's camera frames are first replayed
// through nudge-symmetry with its own flags and then each flag set given (';'-separated; "recorded":
// the lines as recorded), and those lines stand in for the recorded ones. Writes
// docs/results/NAME.{json,md} (default survey_line_tilt). With --triangulation, each ';'-separated
// flag set ("none": none) is added to the replayed nudge-triangulation's command.
// For every survey with a real candidate it also counts whether the first candidate is real when
// they go nearest the right camera first (the thesis) or most intersects first (nudge-supervisor
// --candidate-order support).
//   nudge-exp-survey-line-tilt RUNS_DIR [RUNS_DIR...] [--tilts 1,2,3] [--lines 3,5] [--published 5,8]
//                              [--published-column-uncounted] [--explored-px 8,12] [--column counted,uncounted]
//                              [--symmetry "recorded;--reach-max-tilt 15"] [--triangulation "none;--cluster-min-fraction 0.04"]
//                              [--real-radius 0.03] [--name STEM]
// Later surveys follow what the recorded run did (its pushes, its explored places): a replay
// scores the lines each tilt keeps, not a new run. Choose on development runs only.
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "nudge/bus/symmetry_convert.hpp"
#include "nudge/candidates_request_t.hpp"
#include "nudge/candidates_t.hpp"
#include "nudge/geometry/interesting_locations.hpp"
#include "nudge/geometry/stereo_rig.hpp"
#include "nudge/geometry/workspace.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/sim_state_t.hpp"
#include "nudge/supervisor/scene.hpp"
#include "nudge/symmetry_lines_t.hpp"
#include "report.hpp"
#include "run_logs.hpp"

namespace fs = std::filesystem;
using nudge::experiments::own_directory;
using nudge::experiments::parse_list;
using nudge::experiments::read_channel;
using nudge::experiments::shell_quote;
using nudge::experiments::state_at;
using nudge::supervisor::SceneGeometry;

namespace {

struct Score {
  int surveys = 0, real = 0, phantom = 0;
  std::set<std::string> objects_found;  // objects some survey's candidate stood on
  int objects = 0;
  // Surveys with a real candidate, and of them those whose first candidate is real when the
  // candidates go nearest the right camera first (the thesis' order) or most intersects first.
  int surveys_with_real = 0, first_real_nearest = 0, first_real_strongest = 0;
};

// One replayed setting: the survey-line tilt, the lines per image the surveys pair (0: as the log's
// requests ask), the lines per image published (0: as recorded) and the column's lines (empty: the
// service's default).
struct Variant {
  double tilt = 0;
  int lines = 0;
  int published = 0;
  bool published_column_uncounted = false;  // the column's lines ride along among the `published`
  std::string column;
  double explored_px = 0;  // 0: the service's default
  std::string symmetry;    // nudge-symmetry flags the camera frames are replayed with ("": lines as recorded)
  std::string triangulation;  // more nudge-triangulation flags ("": none)
  bool operator<(const Variant& o) const {
    return std::tie(symmetry, published, published_column_uncounted, lines, column, explored_px, triangulation, tilt) <
           std::tie(o.symmetry, o.published, o.published_column_uncounted, o.lines, o.column, o.explored_px,
                    o.triangulation, o.tilt);
  }
  bool rewritten() const { return lines || published || !symmetry.empty(); }
  std::tuple<int, int, bool, std::string> rewrite() const { return {lines, published, published_column_uncounted, symmetry}; }
  std::string name() const {
    std::ostringstream text;
    text << tilt << "°";
    if (lines) text << " " << lines << " lines";
    if (published) text << " " << published << (published_column_uncounted ? "+column" : "") << " published";
    if (!column.empty()) text << " column " << column;
    if (!symmetry.empty()) text << " symmetry `" << symmetry << "`";
    if (!triangulation.empty()) text << " `" << triangulation << "`";
    if (explored_px > 0) text << " explored " << explored_px << " px";
    return text.str();
  }
};

// A copy of the log whose CANDIDATES_REQUESTs ask for `lines` lines per image (0: as recorded) and
// whose SYMMETRY messages hold their first `published` lines (0: all): the recorded surveys replayed
// as if the supervisor had run with --survey-lines `lines` and the symmetry service had published
// `published` lines. With `column` (the rig, table and arm base), the arm base column's lines ride
// along uncounted among the `published` (nudge-symmetry --reach-column-px 8).
struct ColumnPlace {
  nudge::geometry::StereoRig rig;
  nudge::geometry::Plane table;
  Eigen::Vector3d foot;
  double px = 8;  // the loop's nudge-symmetry --reach-column-px
};
// SYMMETRY_LEFT/RIGHT lines by channel and image time, replayed (nudge-symmetry with other flags).
using ReplayedLines = std::map<std::pair<std::string, int64_t>, nudge::symmetry_lines_t>;
ReplayedLines replayed_lines(const fs::path& log) {
  ReplayedLines lines;
  for (const std::string channel : {"SYMMETRY_LEFT", "SYMMETRY_RIGHT"})
    for (auto& m : read_channel<nudge::symmetry_lines_t>(log, channel)) lines[{channel, m.utime}] = std::move(m);
  return lines;
}

// With `replayed`, each recorded SYMMETRY message is replaced by the replayed one of its image
// (none: dropped) before the cut to `published`.
void write_with_survey_lines(const fs::path& from, const fs::path& to, int lines, int published,
                             const ColumnPlace* column, const ReplayedLines* replayed) {
  lcm::LogFile in(from.string(), "r");
  lcm::LogFile out(to.string(), "w");
  if (!in.good() || !out.good()) throw std::runtime_error("cannot copy " + from.string() + " to " + to.string());
  std::vector<uint8_t> buffer;
  for (const lcm::LogEvent* e = in.readNextEvent(); e; e = in.readNextEvent()) {
    lcm::LogEvent copy = *e;
    nudge::candidates_request_t request;
    nudge::symmetry_lines_t symmetry;
    auto replace = [&](const auto& message) {
      buffer.resize(message.getEncodedSize());
      message.encode(buffer.data(), 0, static_cast<int>(buffer.size()));
      copy.data = buffer.data();
      copy.datalen = static_cast<int32_t>(buffer.size());
    };
    if (lines && e->channel == "CANDIDATES_REQUEST" && request.decode(e->data, 0, e->datalen) >= 0) {
      request.lines_per_image = lines;
      replace(request);
    }
    const bool is_symmetry = e->channel.rfind("SYMMETRY_", 0) == 0 && symmetry.decode(e->data, 0, e->datalen) >= 0;
    if (is_symmetry && replayed) {
      const auto it = replayed->find({e->channel, symmetry.utime});
      if (it == replayed->end()) continue;
      symmetry = it->second;
      replace(symmetry);
    }
    if (published && is_symmetry && symmetry.num_lines > published) {
      int kept = published;
      if (column) {
        std::vector<nudge::symmetry::Line> recorded;
        for (const auto& l : symmetry.lines) recorded.push_back(nudge::bus::from_message(l));
        const auto side = e->channel == "SYMMETRY_LEFT" ? nudge::geometry::Side::Left : nudge::geometry::Side::Right;
        kept = static_cast<int>(nudge::geometry::first_lines_column_uncounted(column->rig, side, column->table, recorded,
                                                                              published, column->foot, column->px)
                                    .size());
      }
      symmetry.num_lines = kept;
      symmetry.lines.resize(kept);
      replace(symmetry);
    }
    if (out.writeEvent(&copy) != 0) throw std::runtime_error("cannot write " + to.string());
  }
}

void score_surveys(const std::vector<nudge::candidates_t>& surveys, const std::vector<nudge::sim_state_t>& states,
                   const SceneGeometry& scene, double real_radius, Score* score) {
  const Eigen::Vector3d camera = scene.right_camera_in_world();
  for (const auto& survey : surveys) {
    const nudge::sim_state_t* state = state_at(states, survey.utime);
    if (!state) continue;
    ++score->surveys;
    struct Scored {
      bool real;
      double from_camera;
      int intersects;
    };
    std::vector<Scored> scored;
    for (int i = 0; i < survey.num_candidates; ++i) {
      const Eigen::Vector3d p = scene.table_to_world({survey.position[i][0], survey.position[i][1], survey.position[i][2]});
      double nearest = real_radius;
      std::string object;
      for (const auto& o : state->objects) {
        const double d = std::hypot(o.pose.position[0] - p.x(), o.pose.position[1] - p.y());
        if (d <= nearest) nearest = d, object = o.name;
      }
      scored.push_back({!object.empty(), (p - camera).head<2>().norm(), survey.cluster_size[i]});
      if (object.empty()) {
        ++score->phantom;
      } else {
        ++score->real;
        score->objects_found.insert(object);
      }
    }
    if (std::none_of(scored.begin(), scored.end(), [](const Scored& c) { return c.real; })) continue;
    ++score->surveys_with_real;
    auto nearer = [](const Scored& a, const Scored& b) { return a.from_camera < b.from_camera; };
    auto stronger = [&](const Scored& a, const Scored& b) {
      return a.intersects != b.intersects ? a.intersects > b.intersects : nearer(a, b);
    };
    score->first_real_nearest += std::min_element(scored.begin(), scored.end(), nearer)->real;
    score->first_real_strongest += std::min_element(scored.begin(), scored.end(), stronger)->real;
  }
}

}  // namespace

int main(int argc, char** argv) try {
  std::vector<std::string> run_sets;
  std::vector<double> tilts{1, 1.5, 2, 3, 4, 5, 7};
  std::vector<int> survey_lines;  // empty: as recorded
  std::vector<int> published;     // empty: as recorded
  std::vector<std::string> columns{""};  // "": the service's default
  bool published_column_uncounted = false;
  std::vector<std::string> symmetry_flags{""};  // "": the recorded lines
  std::vector<std::string> triangulation_flags{""};
  std::vector<double> explored_px{0};  // 0: the service's default
  double real_radius = 0.03;
  std::string name = "survey_line_tilt";
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const bool has_value = i + 1 < argc;
    if (arg == "--tilts" && has_value) tilts = parse_list(argv[++i], arg);
    else if (arg == "--lines" && has_value)
      for (double n : parse_list(argv[++i], arg)) survey_lines.push_back(static_cast<int>(n));
    else if (arg == "--published" && has_value)
      for (double n : parse_list(argv[++i], arg)) published.push_back(static_cast<int>(n));
    else if (arg == "--published-column-uncounted") published_column_uncounted = true;
    else if (arg == "--symmetry" && has_value) {
      symmetry_flags.clear();  // the list given replaces the default (the recorded lines alone)
      std::stringstream in(argv[++i]);
      for (std::string flags; std::getline(in, flags, ';');) symmetry_flags.push_back(flags == "recorded" ? "" : flags);
    } else if (arg == "--triangulation" && has_value) {
      triangulation_flags.clear();
      std::stringstream in(argv[++i]);
      for (std::string flags; std::getline(in, flags, ';');) triangulation_flags.push_back(flags == "none" ? "" : flags);
    }
    else if (arg == "--explored-px" && has_value) explored_px = parse_list(argv[++i], arg);
    else if (arg == "--column" && has_value) {
      columns.clear();
      std::stringstream in(argv[++i]);
      for (std::string mode; std::getline(in, mode, ',');) {
        nudge::geometry::parse_column_lines(mode);  // refuses an unknown mode before any replay
        columns.push_back(mode);
      }
    } else if (arg == "--real-radius" && has_value) real_radius = std::stod(argv[++i]);
    else if (arg == "--name" && has_value) name = argv[++i];
    else if (!arg.empty() && arg[0] == '-') throw std::invalid_argument("unknown option " + arg);
    else run_sets.push_back(arg);
  }
  if (run_sets.empty()) {
    std::cerr << "usage: nudge-exp-survey-line-tilt RUNS_DIR [RUNS_DIR...] [--tilts 1,2,3] [--lines 3,5] [--published 5,8] "
                 "[--published-column-uncounted] [--explored-px 8,12] [--column counted,dropped,uncounted] "
                 "[--symmetry \"recorded;FLAGS...\"] [--triangulation \"none;FLAGS...\"] [--real-radius 0.03] [--name STEM]\n";
    return 2;
  }
  const fs::path source = NUDGE_SOURCE_DIR;
  const std::string calibration = (source / "config/calibration_sim.yaml").string();
  const std::string workspace = (source / "config/workspace.yaml").string();
  const SceneGeometry scene = SceneGeometry::load(calibration);
  const std::string triangulation = (own_directory() / "nudge-triangulation").string();
  const fs::path replay = fs::temp_directory_path() / ("survey_line_tilt_" + std::to_string(getpid()) + ".lcmlog");
  const fs::path rewritten = fs::temp_directory_path() / ("survey_line_tilt_in_" + std::to_string(getpid()) + ".lcmlog");
  // The variants replayed: every tilt at every lines-per-image and lines published (0: as recorded).
  std::vector<Variant> variants;
  for (int kept : published.empty() ? std::vector<int>{0} : published)
    for (bool uncounted : {false, true}) {
      if (uncounted && (!kept || !published_column_uncounted)) continue;
      for (int lines : survey_lines.empty() ? std::vector<int>{0} : survey_lines)
        for (const std::string& column : columns)
          for (double explored : explored_px)
            for (const std::string& flags : symmetry_flags)
              for (const std::string& more : triangulation_flags)
                for (double tilt : tilts) variants.push_back({tilt, lines, kept, uncounted, column, explored, flags, more});
    }
  const nudge::geometry::Workspace place = nudge::geometry::load_workspace(calibration);
  if (!place.table || !place.arm_base) throw std::runtime_error(calibration + " needs table_plane and arm_base");
  const ColumnPlace column_place{nudge::geometry::load_rig(calibration), *place.table,
                                 nudge::geometry::TableFrame(*place.table, *place.arm_base).origin()};

  const auto logs = nudge::experiments::run_logs(run_sets);

  // variant -> run -> score
  std::map<Variant, std::map<std::string, Score>> scores;
  nudge::Progress progress("nudge-exp-survey-line-tilt", static_cast<int>(logs.size()));
  for (const auto& [run, log] : logs) {
    progress.step(run);
    const auto states = read_channel<nudge::sim_state_t>(log, "SIM_STATE");
    if (states.empty()) throw std::runtime_error(log.string() + ": no SIM_STATE (a simulated run's log is needed)");
    std::string line = run + ":";
    std::tuple<int, int, bool, std::string> rewritten_as{0, 0, false, ""};
    std::map<std::string, ReplayedLines> replays;  // symmetry flags -> the lines they give on this run
    for (const Variant& variant : variants) {
      if (variant.rewritten() && variant.rewrite() != rewritten_as) {
        if (!variant.symmetry.empty() && !replays.count(variant.symmetry)) {
          nudge::experiments::replay_symmetry(log, variant.symmetry, replay);
          replays[variant.symmetry] = replayed_lines(replay);
        }
        write_with_survey_lines(log, rewritten, variant.lines, variant.published,
                                variant.published_column_uncounted ? &column_place : nullptr,
                                variant.symmetry.empty() ? nullptr : &replays[variant.symmetry]);
        rewritten_as = variant.rewrite();
      }
      const fs::path& input = variant.rewritten() ? rewritten : log;
      const std::string command = shell_quote(triangulation) + " --lcm-in " + shell_quote("file://" + input.string() + "?speed=0") +
                                  " --lcm-out " + shell_quote("file://" + replay.string() + "?mode=w") + " --calibration " +
                                  shell_quote(calibration) + " --workspace " + shell_quote(workspace) +
                                  " --candidate-line-tilt " + std::to_string(variant.tilt) +
                                  (variant.column.empty() ? std::string() : " --candidate-column-lines " + variant.column) +
                                  (variant.explored_px > 0 ? " --candidate-explored-px " + std::to_string(variant.explored_px) : std::string()) +
                                  (variant.triangulation.empty() ? std::string() : " " + variant.triangulation) +
                                  " >/dev/null 2>&1";
      if (std::system(command.c_str()) != 0) throw std::runtime_error("nudge-triangulation failed on " + log.string());
      Score& s = scores[variant][run];
      s.objects = static_cast<int>(states.front().objects.size());
      score_surveys(read_channel<nudge::candidates_t>(replay, "CANDIDATES"), states, scene, real_radius, &s);
      line += " " + variant.name() + ": " + std::to_string(s.real) + "/" + std::to_string(s.phantom);
    }
    progress.note(line);
  }
  progress.finish(std::to_string(logs.size()) + " runs replayed at " + std::to_string(variants.size()) + " settings");
  fs::remove(replay);
  fs::remove(rewritten);

  nudge::JsonWriter json(4);
  json.begin_object().field("machine", nudge::experiments::machine_description()).field("date", nudge::experiments::today());
  json.field("runs", static_cast<int>(logs.size())).field("real_radius_m", real_radius).key("variants").begin_array();
  std::ostringstream md;
  md << "# Survey lines: candidates kept at each `--candidate-line-tilt` and lines per image\n\n"
     << "`nudge-exp-survey-line-tilt` replayed each recorded run's log through `nudge-triangulation` at each tilt "
        "and number of lines per image (the run's own SYMMETRY lines and CANDIDATES_REQUESTs; `as recorded`: the "
        "requests' own lines per image, else each request rewritten to ask for that many) and scored every survey's candidates against the "
        "simulator's state: within " << real_radius * 1000 << " mm of an object it is real, else a phantom. Later "
        "surveys follow what the recorded run did. Runs: ";
  for (size_t i = 0; i < run_sets.size(); ++i) md << (i ? ", " : "") << i + 1 << ": `" << run_sets[i] << "`";
  md << " (" << logs.size() << " runs). " << nudge::experiments::machine_description() << ", "
     << nudge::experiments::today() << ".\n\n"
     << "| symmetry replayed with | tilt (deg) | lines per image | lines published | column's lines | explored objects' lines within (px) | more triangulation flags | real candidates | phantoms | objects ever a candidate | first candidate real, nearest the camera first / most intersects first (of surveys with a real one) |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [variant, runs] : scores) {
    int real = 0, phantom = 0, found = 0, objects = 0, with_real = 0, nearest = 0, strongest = 0;
    for (const auto& [run, s] : runs) {
      real += s.real, phantom += s.phantom, found += static_cast<int>(s.objects_found.size()), objects += s.objects;
      with_real += s.surveys_with_real, nearest += s.first_real_nearest, strongest += s.first_real_strongest;
    }
    md << "| " << (variant.symmetry.empty() ? std::string("(as recorded)") : "`" + variant.symmetry + "`") << " | "
       << variant.tilt << " | " << (variant.lines ? std::to_string(variant.lines) : "as recorded") << " | "
       << (variant.published ? std::to_string(variant.published) + (variant.published_column_uncounted ? " + column" : "")
                             : "as recorded") << " | "
       << (variant.column.empty() ? "default" : variant.column) << " | "
       << (variant.explored_px > 0 ? std::to_string(std::lround(variant.explored_px)) : std::string("default")) << " | "
       << (variant.triangulation.empty() ? std::string("–") : "`" + variant.triangulation + "`") << " | " << real
       << " | " << phantom << " | " << found << "/" << objects << " | " << nearest << " / " << strongest << " of "
       << with_real << " |\n";
    json.begin_object().field("tilt_deg", variant.tilt).field("lines_per_image", variant.lines).field("lines_published", variant.published);
    json.field("published_column_uncounted", variant.published_column_uncounted);
    json.field("column_lines", variant.column.empty() ? std::string("default") : variant.column);
    json.field("explored_line_px", variant.explored_px).field("symmetry_flags", variant.symmetry);
    json.field("triangulation_flags", variant.triangulation);
    json.field("real", real).field("phantoms", phantom);
    json.field("objects_found", found).field("objects", objects);
    json.field("surveys_with_real", with_real).field("first_real_nearest", nearest).field("first_real_strongest", strongest).end_object();
  }
  json.end_array().end_object();
  md << "\nPer run (set:scene; real/phantoms, and objects ever a candidate):\n\n| run |";
  for (const auto& [variant, runs] : scores) md << " " << variant.name() << " |";
  md << "\n|---|";
  for (size_t i = 0; i < scores.size(); ++i) md << "---|";
  md << "\n";
  for (const auto& [run, log] : logs) {
    md << "| " << run << " |";
    for (auto& [variant, runs] : scores) {
      const Score& s = runs[run];
      md << " " << s.real << "/" << s.phantom << " (" << s.objects_found.size() << "/" << s.objects << ") |";
    }
    md << "\n";
  }
  nudge::experiments::write_result(name + ".json", json.str() + "\n");
  nudge::experiments::write_result(name + ".md", md.str());
  return 0;
} catch (const std::exception& e) {
  std::cerr << "nudge-exp-survey-line-tilt: " << e.what() << "\n";
  return 1;
}
