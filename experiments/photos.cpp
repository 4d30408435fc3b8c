// Symmetry on photographs scored with the symmetry competitions' rule (angle within 10 deg, centre
// within 0.2 x the shorter segment): the top line of fast symmetry (nudge-detect's defaults, no
// tuning) against the top line of Loy & Eklundh's SIFT mirror matching (2006), and their times.
//   nudge-exp-photos [--annotations CSV] [--name photos]
// CSV rows: path, x1, y1, x2, y2 (one annotated axis per image; '#' starts a comment). Writes
// docs/results/NAME.{json,md}. Point it at a published dataset's annotations for real numbers.
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/symmetry/loy_eklundh.hpp"
#include "nudge/symmetry/photo.hpp"
#include "nudge/timing.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace sym = nudge::symmetry;

namespace {

struct Annotated {
  std::string path;
  cv::Point2d a, b;
};

std::vector<Annotated> read_annotations(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file);
  std::vector<Annotated> rows;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    std::stringstream ss(line);
    std::vector<std::string> cells;
    for (std::string cell; std::getline(ss, cell, ',');) cells.push_back(cell);
    if (cells.size() != 5) throw std::runtime_error(file + ":" + std::to_string(number) + ": expected path,x1,y1,x2,y2");
    Annotated row;
    row.path = cells[0];
    const std::string where = file + ":" + std::to_string(number);
    row.a = {parse_double(cells[1].substr(cells[1].find_first_not_of(' ')), where),
             parse_double(cells[2].substr(cells[2].find_first_not_of(' ')), where)};
    row.b = {parse_double(cells[3].substr(cells[3].find_first_not_of(' ')), where),
             parse_double(cells[4].substr(cells[4].find_first_not_of(' ')), where)};
    rows.push_back(row);
  }
  return rows;
}


// The same rule for every method, whatever support segment it reports: angle within 10 deg and the
// annotated axis' midpoint within 0.2 x the annotated length of the detected (infinite) line. The
// competitions' rule also needs the detected segment's centre near the annotated one, which
// penalises a method whose support segment is short (Loy & Eklundh's: its few matched SIFT pairs).
bool line_match(const sym::Line& detected, const cv::Point2d& truth_a, const cv::Point2d& truth_b) {
  const cv::Point2d truth_dir = truth_b - truth_a;
  const cv::Point2d line_dir = detected.end2 - detected.end1;
  const double lengths = std::max(1e-12, cv::norm(truth_dir) * cv::norm(line_dir));
  const double angle_deg = std::acos(std::min(1.0, std::fabs(truth_dir.dot(line_dir)) / lengths)) * 180.0 / M_PI;
  const cv::Point2d mid = 0.5 * (truth_a + truth_b) - detected.end1;
  const double distance = std::fabs(line_dir.x * mid.y - line_dir.y * mid.x) / std::max(1e-12, cv::norm(line_dir));
  return angle_deg < 10.0 && distance < 0.2 * cv::norm(truth_dir);
}

struct Method {
  std::string key, title;
  std::vector<bool> hits;
  std::vector<bool> line_hits;  // by line_match
  std::vector<double> ms;
  std::vector<std::string> cells;  // the table's cell per image
  int hit_count() const { return static_cast<int>(std::count(hits.begin(), hits.end(), true)); }
  int line_hit_count() const { return static_cast<int>(std::count(line_hits.begin(), line_hits.end(), true)); }
};

std::string describe(const std::vector<sym::Line>& lines, bool ok) {
  if (lines.empty()) return "none";
  std::ostringstream s;
  s.precision(4);
  s << (ok ? "hit" : "miss") << " (R " << lines[0].r << ", θ " << lines[0].theta * 180 / M_PI << "°)";
  return s.str();
}

void score(Method& m, const std::vector<sym::Line>& lines, const Annotated& row, double ms) {
  const bool ok = !lines.empty() && sym::competition_match(lines[0], row.a, row.b);
  m.hits.push_back(ok);
  m.line_hits.push_back(!lines.empty() && line_match(lines[0], row.a, row.b));
  m.ms.push_back(ms);
  std::ostringstream cell;
  cell << describe(lines, ok) << ", " << std::fixed << std::setprecision(1) << ms << " ms";
  m.cells.push_back(cell.str());
}

// The 1-minute load average (/proc/loadavg), recorded with the times.
std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string first;
  return in >> first ? first : "unknown";
}

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

sym::PhotoOptions options_with_mirror(double tolerance_deg, bool polarity = false) {
  sym::PhotoOptions options;
  options.params.num_lines = 1;
  options.params.mirror_tolerance_deg = tolerance_deg;
  options.params.mirror_polarity = polarity;
  return options;
}

}  // namespace

int main(int argc, char** argv) {
  std::string annotations = std::string(NUDGE_SOURCE_DIR) + "/experiments/data/photo_axes.csv";
  std::string name = "photos";
  Flags flags("nudge-exp-photos", "Fast symmetry against Loy & Eklundh (2006) on annotated photographs.");
  flags.add_string("annotations", &annotations, "CSV of path, x1, y1, x2, y2");
  flags.add_string("name", &name, "result file name (docs/results/NAME.json)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    const auto rows = read_annotations(annotations);
    const double default_tolerance = sym::PhotoOptions{}.params.mirror_tolerance_deg;
    const std::vector<double> sweep = {5, 10, 15, 20, 30, 45};
    Method fast{"fast", "fast symmetry (defaults: mirror rule " + format_number(default_tolerance) + "°)", {}, {}, {}, {}};
    Method plain{"fast_locations_only", "fast symmetry, locations only (Algorithm 1)", {}, {}, {}, {}};
    Method le{"loy_eklundh", "Loy & Eklundh", {}, {}, {}, {}};
    std::vector<int> sweep_hits(sweep.size(), 0), polarity_hits(sweep.size(), 0);  // polarity: Params::mirror_polarity
    std::vector<std::string> files;
    nudge::Progress progress("nudge-exp-photos", static_cast<int>(rows.size()));
    for (const auto& row : rows) {
      progress.step(row.path.substr(row.path.rfind('/') + 1));
      const cv::Mat image = cv::imread(row.path, cv::IMREAD_COLOR);
      if (image.empty()) {
        progress.note("skipped " + row.path + ": cannot read it");
        continue;
      }
      files.push_back(row.path.substr(row.path.rfind('/') + 1));
      // Each method's lines first, then its time (a function's arguments have no evaluation order).
      Stopwatch watch;
      const auto fast_lines = sym::detect_photo(image, options_with_mirror(default_tolerance)).in_image.lines;
      score(fast, fast_lines, row, watch.lap_ms());
      const auto plain_lines = sym::detect_photo(image, options_with_mirror(0)).in_image.lines;
      score(plain, plain_lines, row, watch.lap_ms());
      const auto le_lines = sym::loy_eklundh(image, sym::LoyEklundhParams{1});
      score(le, le_lines, row, watch.lap_ms());
      for (size_t t = 0; t < sweep.size(); ++t) {
        const auto lines = sym::detect_photo(image, options_with_mirror(sweep[t])).in_image.lines;
        sweep_hits[t] += !lines.empty() && sym::competition_match(lines[0], row.a, row.b);
        const auto polar = sym::detect_photo(image, options_with_mirror(sweep[t], true)).in_image.lines;
        polarity_hits[t] += !polar.empty() && sym::competition_match(polar[0], row.a, row.b);
      }
      progress.note(files.back() + ": fast " + (fast.hits.back() ? "hit" : "miss") + ", locations only " +
                    (plain.hits.back() ? "hit" : "miss") + ", Loy-Eklundh " + (le.hits.back() ? "hit" : "miss"));
    }
    progress.clear_status();  // the result files' "wrote" lines follow on stderr
    const int images = static_cast<int>(files.size());
    if (images == 0) throw std::runtime_error("no readable images in " + annotations);
    JsonWriter j;
    j.begin_object();
    j.field("machine", machine_description()).field("date", today());
    j.field("annotations", annotations.substr(annotations.rfind('/') + 1));
    j.field("images", images);
    for (const Method* m : {&fast, &plain, &le}) {
      j.key(m->key).begin_object().field("top_line_hits", m->hit_count());
      j.field("top_line_hits_line_rule", m->line_hit_count());
      j.field("hit_rate", double(m->hit_count()) / images).field("median_ms", median(m->ms)).end_object();
    }
    j.field("mirror_tolerance_deg", default_tolerance);
    j.key("mirror_tolerance_sweep").begin_array();
    for (size_t t = 0; t < sweep.size(); ++t)
      j.begin_object().field("tolerance_deg", sweep[t]).field("top_line_hits", sweep_hits[t])
          .field("top_line_hits_with_polarity", polarity_hits[t]).end_object();
    j.end_array();
    j.field("time_ratio_le_over_fast", median(le.ms) / median(fast.ms));
    j.end_object();
    write_result(name + ".json", j.str() + "\n");

    std::ostringstream md;
    md << "# Symmetry on photographs: fast symmetry against Loy & Eklundh (2006)\n\n"
       << "Top line of each method scored with the symmetry competitions' rule (angle within 10°, centre "
          "within 0.2 × the shorter segment). Fast symmetry runs with `nudge-detect`'s defaults (working size "
          "480 px, automatic Canny thresholds, Dmin/Dmax relative to the image, and only pairs whose edge "
          "orientations mirror about the axis within " << format_number(default_tolerance) << "° vote), and once more "
          "with edge locations only, as Algorithm 1 is published; Loy & Eklundh is this project's implementation "
          "(`symmetry/loy_eklundh.hpp`: SIFT mirror matching, 1° × 1 px Hough). Annotations: `"
       << annotations.substr(annotations.rfind('/') + 1) << "` (" << images << " images: a small set, "
       << "annotated by eye; point `--annotations` at a published dataset's for real numbers).\n\nMachine: "
       << machine_description() << ", " << today() << ", load average " << load_average()
       << " (times on a machine shared by other jobs run long; their ratios within one run still compare).\n\n| image | " << fast.title << " | " << plain.title
       << " | " << le.title << " |\n|---|---|---|---|\n";
    for (int i = 0; i < images; ++i)
      md << "| " << files[i] << " | " << fast.cells[i] << " | " << plain.cells[i] << " | " << le.cells[i] << " |\n";
    md << "\n| | fast symmetry (defaults) | locations only | Loy & Eklundh |\n|---|---|---|---|\n"
       << "| top line correct | " << fast.hit_count() << " / " << images << " | " << plain.hit_count() << " / "
       << images << " | " << le.hit_count() << " / " << images << " |\n"
       << "| top line correct, line rule (same for all) | " << fast.line_hit_count() << " / " << images << " | "
       << plain.line_hit_count() << " / " << images << " | " << le.line_hit_count() << " / " << images << " |\n"
       << "| median ms per image | " << median(fast.ms) << " | " << median(plain.ms) << " | " << median(le.ms) << " |\n"
       << "\nThe mirror rule's tolerance (top lines correct, of " << images << "), on orientations (the default) "
          "and with the gradients' polarity as well (`mirror_polarity`, `nudge-detect --mirror-polarity`):\n\n"
          "| tolerance | hits | hits with polarity |\n|---|---|---|\n";
    for (size_t t = 0; t < sweep.size(); ++t)
      md << "| " << sweep[t] << "° | " << sweep_hits[t] << " | " << polarity_hits[t] << " |\n";
    md << "\n**How much this shows.** " << images << " images, annotated by eye for this project: a lead of one "
          "image is no evidence that either method is better. The competitions' rule compares the detected "
          "*segment's* centre with the annotated one, so a method is also scored on the extent of its support "
          "segment; the line rule scores every method's line alone (angle within 10°, the annotated midpoint "
          "within 0.2 × the annotated length of the line).";
    for (const Method* m : {&fast, &plain, &le})
      for (int i = 0; i < images; ++i)
        if (m->hits[i] != m->line_hits[i])
          md << " " << m->title << " on " << files[i] << ": " << (m->line_hits[i] ? "a hit" : "a miss")
             << " by the line rule, " << (m->hits[i] ? "a hit" : "a miss") << " by the competitions' rule"
             << (m->line_hits[i] ? " (its support segment is too short or off-centre)" : "") << ".";
    md << "\n";
    write_result(name + ".md", md.str());
    progress.finish(std::to_string(images) + " images: top line correct, fast " + std::to_string(fast.hit_count()) +
                    ", locations only " + std::to_string(plain.hit_count()) + ", Loy-Eklundh " +
                    std::to_string(le.hit_count()));
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-photos: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
