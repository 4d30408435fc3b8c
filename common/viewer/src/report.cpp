#include "nudge/viewer/report.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <sstream>
#include <stdexcept>

namespace nudge::viewer {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string escape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

json read_json(const fs::path& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read " + path.string());
  try {
    return json::parse(in);
  } catch (const json::parse_error& e) {
    throw std::runtime_error(path.string() + " is not JSON: " + e.what());
  }
}

std::string fixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

std::string number(const json& j, const std::string& key, int digits = 0) {
  if (!j.contains(key) || !j[key].is_number()) return "–";
  return fixed(j[key].get<double>(), digits);
}

std::string text_of(const json& j, const std::string& key) {
  if (!j.contains(key) || j[key].is_null()) return "–";
  return escape(j[key].is_string() ? j[key].get<std::string>() : j[key].dump());
}

// An <img> of `relative` (from the report's folder) when the file exists.
std::string picture(const fs::path& run_dir, const std::string& relative, const std::string& caption) {
  if (!fs::exists(run_dir / relative)) return "";
  return "<figure><a href=\"" + escape(relative) + "\"><img src=\"" + escape(relative) + "\" alt=\"" + escape(caption) +
         "\"></a><figcaption>" + escape(caption) + "</figcaption></figure>";
}

// θ of each tracker per frame (attempt.json's track_trace) as an SVG plot; empty when the attempt
// tracked nothing.
std::string tracking_plot(const json& attempt) {
  if (!attempt.contains("track_trace") || !attempt["track_trace"].is_object()) return "";
  std::vector<std::pair<std::string, std::vector<std::pair<double, double>>>> series;
  double t_min = 1e300, t_max = -1e300, v_min = 1e300, v_max = -1e300;
  for (const auto& [side, trace] : attempt["track_trace"].items()) {
    if (!trace.is_array()) continue;
    std::vector<std::pair<double, double>> points;
    for (const auto& p : trace) {  // [t_s, status, r, theta, measured, holding] (the supervisor's report)
      if (!p.is_array() || p.size() < 4 || !p[0].is_number() || !p[3].is_number()) continue;
      const double t = p[0].get<double>();
      const double v = p[3].get<double>() * 180 / 3.14159265358979;
      points.emplace_back(t, v);
      t_min = std::min(t_min, t), t_max = std::max(t_max, t), v_min = std::min(v_min, v), v_max = std::max(v_max, v);
    }
    if (!points.empty()) series.emplace_back(side, std::move(points));
  }
  if (series.empty()) return "";
  const double w = 480, h = 160, dt = std::max(t_max - t_min, 1e-6), dv = std::max(v_max - v_min, 1.0);
  std::ostringstream svg;
  svg << "<figure><svg class=\"plot\" viewBox=\"0 0 " << w << " " << h << "\" width=\"" << w << "\" height=\"" << h
      << "\"><rect width=\"" << w << "\" height=\"" << h << "\" fill=\"#fafafa\" stroke=\"#ccc\"/>";
  const char* colours[] = {"#1e88e5", "#e53935", "#43a047"};
  for (size_t i = 0; i < series.size(); ++i) {
    svg << "<polyline fill=\"none\" stroke=\"" << colours[i % 3] << "\" stroke-width=\"1.5\" points=\"";
    for (const auto& [t, v] : series[i].second)
      svg << fixed(10 + (t - t_min) / dt * (w - 20), 1) << "," << fixed(h - 10 - (v - v_min) / dv * (h - 20), 1) << " ";
    svg << "\"/><text x=\"" << 14 + 60 * i << "\" y=\"16\" fill=\"" << colours[i % 3] << "\" font-size=\"12\">"
        << escape(series[i].first) << "</text>";
  }
  svg << "</svg><figcaption>tracked θ, " << fixed(v_min, 1) << "° to " << fixed(v_max, 1) << "°, over "
      << fixed(dt, 1) << " s</figcaption></figure>";
  return svg.str();
}

// A position in metres as "(x, y) mm", as the supervisor prints it.
std::string millimetres(const json& j, const std::string& key) {
  if (!j.contains(key) || !j[key].is_array() || j[key].size() < 2 || !j[key][0].is_number()) return "–";
  return "(" + fixed(j[key][0].get<double>() * 1000, 0) + ", " + fixed(j[key][1].get<double>() * 1000, 0) + ") mm";
}

const SimulationScore* score_of(const std::vector<SimulationScore>& scores, int attempt) {
  for (const SimulationScore& s : scores)
    if (s.attempt == attempt) return &s;
  return nullptr;
}

std::string object_label(const SimulationScore& s) {
  if (s.object < 0) return "no object";
  return escape(s.object_name.empty() ? "object " + std::to_string(s.object) : s.object_name) + " (object " +
         std::to_string(s.object) + ")";
}

// Per object of the scene that some mask covered: the attempts that segmented it with their IoU,
// and the best. An object no mask covered is not listed (the scene's file is not read here).
std::string iou_table(const std::vector<SimulationScore>& scores) {
  std::map<int, std::vector<const SimulationScore*>> by_object;
  for (const SimulationScore& s : scores) by_object[s.object].push_back(&s);
  std::ostringstream out;
  out << "<h2>IoU in simulation, per object</h2><table id=\"iou\"><tr><th>object</th><th>attempts (IoU)</th>"
      << "<th>best IoU</th></tr>";
  for (const auto& [object, list] : by_object) {
    double best = 0;
    std::string attempts;
    for (const SimulationScore* s : list) {
      best = std::max(best, s->iou);
      attempts += (attempts.empty() ? "" : ", ") + std::to_string(s->attempt) + " (" + fixed(s->iou, 3) + ")";
    }
    out << "<tr><td>" << object_label(*list.front()) << "</td><td>" << attempts << "</td><td class=\"best\">"
        << (object < 0 ? "–" : fixed(best, 3)) << "</td></tr>";
  }
  out << "</table>";
  return out.str();
}

// "segmented 2, tipped or lost 1" from summary.json's {"segmented": 2, "tipped or lost": 1}.
std::string outcomes_text(const json& summary) {
  if (!summary.contains("outcomes") || !summary["outcomes"].is_object()) return text_of(summary, "outcomes");
  std::ostringstream out;
  for (const auto& [outcome, count] : summary["outcomes"].items())
    out << (out.tellp() > 0 ? ", " : "") << escape(outcome) << " " << (count.is_number() ? count.dump() : "?");
  return out.str();
}

// Seconds spent in each state over the run (from each transition to the next; the last state's
// time is unknown), in the order the states first came, with how often each was entered.
std::string state_times_table(const std::vector<StateEntry>& states) {
  std::vector<std::string> order;
  std::map<std::string, std::pair<double, int>> time_and_entries;
  for (size_t i = 0; i < states.size(); ++i) {
    auto [it, added] = time_and_entries.try_emplace(states[i].state, 0.0, 0);
    if (added) order.push_back(states[i].state);
    ++it->second.second;
    if (i + 1 < states.size()) it->second.first += (states[i + 1].utime - states[i].utime) * 1e-6;
  }
  std::ostringstream out;
  out << "<h2>time per state</h2><table id=\"state_times\"><tr><th>state</th><th>seconds</th><th>entered</th></tr>";
  for (const std::string& state : order)
    out << "<tr><td>" << escape(state) << "</td><td>" << fixed(time_and_entries[state].first, 1) << "</td><td>"
        << time_and_entries[state].second << "</td></tr>";
  out << "</table>";
  return out.str();
}

// The supervisor's transitions; a run of one state within an attempt (the twelve views' ROTATE)
// is one row: its first and last reasons and how many transitions it was.
std::string timeline_table(const std::vector<StateEntry>& states) {
  std::ostringstream out;
  out << "<h2>timeline</h2><table id=\"timeline\"><tr><th>t (s)</th><th>state</th><th>attempt</th><th>reason</th></tr>";
  for (size_t i = 0; i < states.size();) {
    size_t last = i;
    while (last + 1 < states.size() && states[last + 1].state == states[i].state &&
           states[last + 1].attempt == states[i].attempt)
      ++last;
    const StateEntry& s = states[i];
    out << "<tr><td>" << fixed((s.utime - states.front().utime) * 1e-6, 1) << "</td><td>" << escape(s.state)
        << "</td><td>" << s.attempt << "</td><td>" << escape(s.reason);
    if (last > i) out << " … " << escape(states[last].reason) << " (" << last - i + 1 << " transitions)";
    out << "</td></tr>";
    i = last + 1;
  }
  if (states.empty()) out << "<tr><td colspan=\"4\">no SUPERVISOR_STATE in the run's log</td></tr>";
  out << "</table>";
  return out.str();
}

// With learning (thesis ch. 7): what recognition answered before the nudge and what learning did.
std::string learning_line(const json& attempt) {
  if (!attempt.contains("learning") || !attempt["learning"].is_object()) return "";
  const json& l = attempt["learning"];
  const auto field = [&l](const char* key) {
    return l.contains(key) && l[key].is_string() ? escape(l[key].get<std::string>()) : std::string();
  };
  std::ostringstream out;
  out << "<p class=\"learning\">recognition: "
      << (field("recognised").empty() ? "nothing known (" + field("recognition_reason") + ")"
                                      : "recognised as " + field("recognised"))
      << " · learning: " << text_of(l, "outcome");
  if (!field("reason").empty()) out << " (" << field("reason") << ")";
  if (l.contains("grasp_plan_ms")) out << " · grasp planned in " << number(l, "grasp_plan_ms") << " ms";
  out << "</p>";
  return out.str();
}

std::string attempt_section(const fs::path& run_dir, const json& attempt, const SimulationScore* score) {
  const int n = attempt.value("attempt", 0);
  std::ostringstream dir_name;
  dir_name << "attempt_" << std::setw(2) << std::setfill('0') << n;
  const std::string dir = dir_name.str();
  std::ostringstream out;
  const double started = attempt.value("started_s", 0.0), ended = attempt.value("ended_s", 0.0);
  out << "<section class=\"attempt\" id=\"" << dir << "\"><h2>attempt " << n << ": " << text_of(attempt, "outcome") << "</h2><p>"
      << text_of(attempt, "reason") << " · target " << millimetres(attempt, "target") << ", at rest " << millimetres(attempt, "rest") << " · " << fixed(ended - started, 1)
      << " s (from " << fixed(started, 1) << " s) · mask " << number(attempt, "mask_pixels") << " px · motion frames "
      << number(attempt, "motion_frames");
  if (score) out << " · IoU (simulation) " << fixed(score->iou, 3) << " with " << object_label(*score);
  out << "</p>" << learning_line(attempt) << "<div class=\"row\">";
  out << picture(run_dir, dir + "/before.png", "before") << picture(run_dir, dir + "/after.png", "after")
      << picture(run_dir, dir + "/mask.png", "mask") << picture(run_dir, dir + "/cutout.png", "cut-out")
      << picture(run_dir, dir + "/workspace.png", "the push seen from above (fig. 6.6)") << "</div>";
  if (fs::is_directory(run_dir / dir / "stages")) {
    std::vector<std::string> stages;
    for (const auto& e : fs::directory_iterator(run_dir / dir / "stages"))
      if (e.path().extension() == ".png") stages.push_back(e.path().filename().string());
    std::sort(stages.begin(), stages.end());
    out << "<h3>segmentation stages (fig. 6.7)</h3><div class=\"row\">";
    for (const auto& s : stages) out << picture(run_dir, dir + "/stages/" + s, s.substr(0, s.size() - 4));
    out << "</div>";
  }
  // The learner's matches when it recognised the object before the nudge (thesis fig. 7.10).
  if (fs::exists(run_dir / dir / "recognition_match.png"))
    out << "<h3>recognition</h3><div class=\"row\">"
        << picture(run_dir, dir + "/recognition_match.png", "the still before the nudge (above) matched to its best learned view (below), fig. 7.10")
        << "</div>";
  // Whatever else the attempt's folder holds (learned views, left stills, ...).
  std::vector<std::string> others;
  const std::vector<std::string> shown = {"before.png", "after.png", "mask.png", "cutout.png", "workspace.png", "recognition_match.png"};
  if (fs::is_directory(run_dir / dir))
    for (const auto& e : fs::recursive_directory_iterator(run_dir / dir)) {
      const std::string rel = fs::relative(e.path(), run_dir).string();
      if (e.path().extension() != ".png" || rel.find("/stages/") != std::string::npos) continue;
      if (std::find(shown.begin(), shown.end(), e.path().filename().string()) != shown.end() &&
          e.path().parent_path() == run_dir / dir)
        continue;
      others.push_back(rel);
    }
  std::sort(others.begin(), others.end());
  // The views the learner was given (thesis ch. 7: twelve, a turn of the wrist apart) first.
  const auto views_end = std::stable_partition(others.begin(), others.end(), [&](const std::string& rel) {
    return rel.rfind(dir + "/views/", 0) == 0;
  });
  const std::vector<std::string> views(others.begin(), views_end), rest(views_end, others.end());
  if (!views.empty()) {
    out << "<h3>learned views (" << views.size() << ")</h3><div class=\"row\">";
    for (const auto& v : views) out << picture(run_dir, v, v.substr(dir.size() + 1));
    out << "</div>";
  }
  if (!rest.empty()) {
    out << "<h3>more pictures</h3><div class=\"row\">";
    for (const auto& o : rest) out << picture(run_dir, o, o.substr(dir.size() + 1));
    out << "</div>";
  }
  const std::string plot = tracking_plot(attempt);
  if (!plot.empty()) out << "<h3>tracking</h3>" << plot;
  out << "</section>";
  return out.str();
}

}  // namespace

std::string render_run_report(const std::string& run_dir_name, const std::vector<StateEntry>& states,
                              const std::vector<SimulationScore>& scores) {
  const fs::path run_dir(run_dir_name);
  const json summary = read_json(run_dir / "summary.json");
  std::ostringstream out;
  const std::string run = summary.contains("run_id") ? text_of(summary, "run_id") : escape(run_dir.filename().string());
  out << "<!doctype html><html lang=\"en\"><head><meta charset=\"utf-8\"><title>nudge run " << run << "</title><style>"
      << "body{font:14px/1.4 system-ui,sans-serif;margin:16px;color:#222}table{border-collapse:collapse}"
      << "td,th{border-bottom:1px solid #ddd;padding:2px 8px;text-align:left}.row{display:flex;flex-wrap:wrap;gap:8px}"
      << "figure{margin:0}figure img{max-width:240px;max-height:180px;border:1px solid #999}"
      << "figcaption{font-size:12px;color:#555}section.attempt{border-top:2px solid #263238;margin-top:16px}"
      << "</style></head><body><h1>nudge run " << run << "</h1>";
  out << "<table id=\"figures\"><tr><th>objects segmented</th><td>" << number(summary, "segmented")
      << "</td></tr><tr><th>nudges (attempts)</th><td>" << number(summary, "attempts") << "</td></tr><tr><th>surveys</th><td>"
      << number(summary, "surveys") << "</td></tr><tr><th>end</th><td>" << text_of(summary, "end_reason")
      << "</td></tr><tr><th>outcomes</th><td>" << outcomes_text(summary) << "</td></tr>";
  if (summary.contains("learned"))
    out << "<tr><th>objects learned</th><td>" << number(summary, "learned") << "</td></tr>";
  if (summary.contains("iou")) out << "<tr><th>IoU (simulation)</th><td>" << text_of(summary, "iou") << "</td></tr>";
  out << "</table>";
  if (!scores.empty()) out << iou_table(scores);
  if (!states.empty()) out << state_times_table(states);
  out << timeline_table(states);
  if (summary.contains("attempt_list") && summary["attempt_list"].is_array())
    for (const auto& attempt : summary["attempt_list"])
      out << attempt_section(run_dir, attempt, score_of(scores, attempt.value("attempt", 0)));
  out << "</body></html>\n";
  return out.str();
}

}  // namespace nudge::viewer
