// Reproduces thesis Table 4.1 (segmentation time per symmetry line on 640x480 frames: mean 94 642
// edge pairs, 35 ms mean on a 2.2 GHz Xeon, unoptimised build) on this machine.
//   nudge-exp-table4_1 [--frames 11] [--lines 5] [--repeats 7] [--clutter 4]
// Frames: synthetic::indoor_scene (as Table 3.1); lines from the ch. 3 detector (Dmin 25, Dmax 250,
// full 180 deg). Each line is segmented with MAXw = the image width (the thesis' timing trials) and,
// for comparison, with MAXw = Dmax = 250 px (its usual setting). Writes docs/results/table4_1.{json,md}.
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/progress.hpp"
#include "nudge/segmentation/segment.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/symmetry/synthetic.hpp"
#include "nudge/timing.hpp"
#include "report.hpp"

using namespace nudge;
using namespace nudge::experiments;
namespace sym = nudge::symmetry;
namespace seg = nudge::segmentation;

namespace {

struct LineTiming {
  int frame = 0, line = 0, edges = 0;
  long long edge_pairs = 0;  // pairs formed by the SEPT (width <= MAXw), the thesis' count
  double ms = 0;             // median of the repeats: SEPT + DP + backtracking + refinement
  int contour_cells = 0;
};

struct Setting {
  double max_width;
  std::vector<LineTiming> lines;
  std::vector<double> ms() const {
    std::vector<double> v;
    for (const auto& l : lines) v.push_back(l.ms);
    return v;
  }
  std::vector<double> pairs() const {
    std::vector<double> v;
    for (const auto& l : lines) v.push_back(static_cast<double>(l.edge_pairs));
    return v;
  }
};

LineTiming time_line(const seg::Segmenter& segmenter, const sym::EdgeSet& edges, const sym::Line& line, int repeats) {
  LineTiming t;
  t.edges = static_cast<int>(edges.points.size());
  t.edge_pairs = segmenter.sept(edges, line).num_pairs;
  std::vector<double> runs;
  for (int r = 0; r < repeats; ++r) {
    Stopwatch w;
    const seg::Contour contour = segmenter.segment(edges, line);
    runs.push_back(w.elapsed_ms());
    t.contour_cells = static_cast<int>(contour.cells.size());
  }
  t.ms = median(runs);
  return t;
}

void run_setting(Setting* setting, const std::vector<sym::EdgeSet>& edges,
                 const std::vector<std::vector<sym::Line>>& lines, int repeats, nudge::Progress& progress) {
  seg::SegmentParams params;
  params.max_width = setting->max_width;
  const seg::Segmenter segmenter(params);
  for (size_t f = 0; f < edges.size(); ++f) {
    progress.step("MAXw " + std::to_string(setting->max_width) + ", frame " + std::to_string(f + 1));
    for (size_t l = 0; l < lines[f].size(); ++l) {
      LineTiming t = time_line(segmenter, edges[f], lines[f][l], repeats);
      t.frame = static_cast<int>(f + 1);
      t.line = static_cast<int>(l + 1);
      setting->lines.push_back(t);
      std::ostringstream line;
      line << "MAXw " << setting->max_width << ", frame " << t.frame << " line " << t.line << ": " << t.edge_pairs
           << " edge pairs, " << t.ms << " ms";
      progress.note(line.str());
    }
  }
}

void write_results(const Setting& wide, const Setting& usual, int frames, int repeats) {
  JsonWriter j;
  j.begin_object();
  j.field("machine", machine_description()).field("date", today()).field("frames", frames);
  j.field("lines", static_cast<int>(wide.lines.size())).field("max_width_px", wide.max_width);
  j.field("mean_ms_per_line", mean(wide.ms())).field("median_ms_per_line", median(wide.ms()));
  j.field("mean_edge_pairs", mean(wide.pairs()));
  j.field("mean_ms_per_line_maxw_dmax", mean(usual.ms())).field("mean_edge_pairs_maxw_dmax", mean(usual.pairs()));
  j.field("thesis_mean_ms", 35.0).field("thesis_mean_edge_pairs", 94642);
  j.end_object();
  write_result("table4_1.json", j.str() + "\n");

  std::ostringstream md;
  md << "# Table 4.1 — segmentation time per symmetry line, 640×480 frames\n\n"
     << "Frames: `synthetic::indoor_scene` seeds 1–" << frames << " (clutter 4, as Table 3.1), Canny 30/90 after a "
     << "σ = 1 blur; lines: the ch. 3 detector's top 5 per frame (Dmin 25, Dmax 250, full 180°). Time = SEPT + "
        "DP + backtracking + refinement for one line, median of "
     << repeats << " runs; edge pairs = pairs the SEPT forms (width ≤ MAXw). Default DP rewards and MAXmid 3 px.\n\n"
     << "Machine: " << machine_description() << ", " << today() << ". Single thread.\n\n"
     << "| | this machine, MAXw = 640 (image width) | this machine, MAXw = 250 (Dmax) | thesis (Xeon 2.2 GHz) |\n"
     << "|---|---|---|---|\n"
     << "| lines segmented | " << wide.lines.size() << " | " << usual.lines.size() << " | – |\n"
     << "| mean edge pairs | " << mean(wide.pairs()) << " | " << mean(usual.pairs()) << " | 94 642 |\n"
     << "| mean ms per line | " << mean(wide.ms()) << " | " << mean(usual.ms()) << " | 35 |\n"
     << "| median ms per line | " << median(wide.ms()) << " | " << median(usual.ms()) << " | – |\n\n"
     << "| frame | line | edges | edge pairs (MAXw 640) | ms (MAXw 640) | ms (MAXw 250) | contour cells |\n"
     << "|---|---|---|---|---|---|---|\n";
  for (size_t i = 0; i < wide.lines.size(); ++i) {
    const auto& w = wide.lines[i];
    md << "| " << w.frame << " | " << w.line << " | " << w.edges << " | " << w.edge_pairs << " | " << w.ms << " | "
       << usual.lines[i].ms << " | " << w.contour_cells << " |\n";
  }
  write_result("table4_1.md", md.str());
}

}  // namespace

int main(int argc, char** argv) {
  int frames = 11, num_lines = 5, repeats = 7, clutter = 4;
  Flags flags("nudge-exp-table4_1", "Thesis Table 4.1 (segmentation time per line) on this machine.");
  flags.add_int("frames", &frames, "number of 640x480 frames");
  flags.add_int("lines", &num_lines, "symmetry lines segmented per frame");
  flags.add_int("repeats", &repeats, "timed runs per line (median)");
  flags.add_int("clutter", &clutter, "scene clutter level (edge density)");
  try {
    if (!flags.parse(argc, argv)) return 0;
    if (frames < 1 || num_lines < 1 || repeats < 1) throw FlagError("--frames, --lines and --repeats must be >= 1");
    sym::Params detect;
    detect.dmin = 25;
    detect.dmax = 250;
    detect.num_lines = num_lines;
    sym::Detector detector(detect);
    std::vector<sym::EdgeSet> edges;
    std::vector<std::vector<sym::Line>> lines;
    for (int i = 0; i < frames; ++i) {
      edges.push_back(sym::detect_edges(sym::synthetic::indoor_scene(1 + i, 640, 480, clutter),
                                        sym::EdgeParams{1.0, 30, 90, false}));
      lines.push_back(detector.detect(edges.back()).lines);
    }
    Setting wide{640, {}}, usual{250, {}};
    nudge::Progress progress("nudge-exp-table4_1", 2 * frames);  // each frame at both widths
    run_setting(&wide, edges, lines, repeats, progress);
    run_setting(&usual, edges, lines, repeats, progress);
    if (wide.lines.empty()) throw std::runtime_error("the detector found no lines to segment");
    progress.clear_status();  // the result files' "wrote" lines follow on stderr
    write_results(wide, usual, frames, repeats);
    progress.finish(std::to_string(wide.lines.size()) + " line(s) segmented at MAXw 640 and 250");
  } catch (const std::exception& e) {
    std::cerr << "nudge-exp-table4_1: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
