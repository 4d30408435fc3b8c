// Symmetry on photographs scored with the symmetry competitions' rule (angle within 10 deg, centre
// within 0.2 x the shorter segment): the top line of fast symmetry (nudge-detect's defaults, no
// tuning) against the top line of Loy & Eklundh's SIFT mirror matching (2006), and their times.
//   nudge-exp-photos [--annotations CSV] [--name photos]
// CSV rows: path, x1, y1, x2, y2 (one annotated axis per image; '#' starts a comment). Writes
// docs/results/NAME.{json,md}. Point it at a published dataset's annotations for real numbers.
#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
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

}  // namespace

int main(int argc, char** argv) {
  std::string annotations = std::string(NUDGE_SOURCE_DIR) + "/experiments/data/photo_axes.csv", name = "photos";
  Flags flags("nudge-exp-photos", "Fast symmetry against Loy & Eklundh (2006) on annotated photographs.");
  flags.add_string("annotations", &annotations, "CSV of path, x1, y1, x2, y2");
  flags.add_string("name", &name, "result file name (docs/results/NAME.json)");
  double mirror_tolerance = sym::PhotoOptions{}.params.mirror_tolerance_deg;
  flags.add_double("mirror-tolerance", &mirror_tolerance, "fast symmetry's mirror rule, degrees (0: off)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    const auto rows = read_annotations(annotations);
    int fast_hits = 0, le_hits = 0, images = 0;
    std::vector<double> fast_ms, le_ms;
    std::ostringstream table;
    table << "| image | fast symmetry top line | ms | Loy & Eklundh top line | ms |\n|---|---|---|---|---|\n";
    for (const auto& row : rows) {
      const cv::Mat image = cv::imread(row.path, cv::IMREAD_COLOR);
      if (image.empty()) {
        std::cerr << "skipped " << row.path << ": cannot read it\n";
        continue;
      }
      ++images;
      sym::PhotoOptions options;
      options.params.num_lines = 1;
      options.params.mirror_tolerance_deg = mirror_tolerance;
      Stopwatch watch;
      const sym::PhotoDetection fast = sym::detect_photo(image, options);
      fast_ms.push_back(watch.lap_ms());
      const auto le = sym::loy_eklundh(image, sym::LoyEklundhParams{1});
      le_ms.push_back(watch.lap_ms());
      const bool fast_ok = !fast.in_image.lines.empty() && sym::competition_match(fast.in_image.lines[0], row.a, row.b);
      const bool le_ok = !le.empty() && sym::competition_match(le[0], row.a, row.b);
      fast_hits += fast_ok;
      le_hits += le_ok;
      auto describe = [](const std::vector<sym::Line>& lines, bool ok) {
        if (lines.empty()) return std::string("none");
        std::ostringstream s;
        s.precision(4);
        s << (ok ? "hit" : "miss") << " (R " << lines[0].r << ", θ " << lines[0].theta * 180 / M_PI << "°)";
        return s.str();
      };
      const std::string file = row.path.substr(row.path.rfind('/') + 1);
      table << "| " << file << " | " << describe(fast.in_image.lines, fast_ok) << " | " << fast_ms.back() << " | "
            << describe(le, le_ok) << " | " << le_ms.back() << " |\n";
      std::cout << file << ": fast " << (fast_ok ? "hit" : "miss") << ", Loy-Eklundh " << (le_ok ? "hit" : "miss") << "\n";
    }
    if (images == 0) throw std::runtime_error("no readable images in " + annotations);
    JsonWriter j;
    j.begin_object();
    j.field("machine", machine_description()).field("date", today());
    j.field("annotations", annotations.substr(annotations.rfind('/') + 1));
    j.field("images", images);
    j.key("fast").begin_object().field("top_line_hits", fast_hits).field("hit_rate", double(fast_hits) / images);
    j.field("median_ms", median(fast_ms)).end_object();
    j.key("loy_eklundh").begin_object().field("top_line_hits", le_hits).field("hit_rate", double(le_hits) / images);
    j.field("median_ms", median(le_ms)).end_object();
    j.field("time_ratio_le_over_fast", median(le_ms) / median(fast_ms));
    j.end_object();
    write_result(name + ".json", j.str() + "\n");
    std::ostringstream md;
    md << "# Symmetry on photographs: fast symmetry against Loy & Eklundh (2006)\n\n"
       << "Top line of each method scored with the symmetry competitions' rule (angle within 10°, centre "
          "within 0.2 × the shorter segment). Fast symmetry runs with `nudge-detect`'s defaults (working size "
          "480 px, automatic Canny thresholds, Dmin/Dmax relative to the image); Loy & Eklundh is this "
          "project's implementation (`symmetry/loy_eklundh.hpp`: SIFT mirror matching, 1° × 1 px Hough). "
          "Annotations: `" << annotations.substr(annotations.rfind('/') + 1) << "`.\n\nMachine: "
       << machine_description() << ", " << today() << ".\n\n" << table.str()
       << "\n| | fast symmetry | Loy & Eklundh |\n|---|---|---|\n"
       << "| top line correct | " << fast_hits << " / " << images << " | " << le_hits << " / " << images << " |\n"
       << "| median ms per image | " << median(fast_ms) << " | " << median(le_ms) << " |\n";
    write_result(name + ".md", md.str());
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-photos: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
