// nudge-detect: bilateral symmetry lines of photographs, one JSON object per image on stdout.
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iostream>
#include <sstream>

#include "nudge/flags.hpp"
#include "nudge/json.hpp"
#include "nudge/log.hpp"
#include "nudge/symmetry/detector.hpp"
#include "nudge/timing.hpp"

using namespace nudge;
namespace sym = nudge::symmetry;

namespace {

struct Options {
  sym::Params params;
  sym::EdgeParams edge;
  std::vector<double> canny;
  std::string draw, accumulator, voters, edges_out, skew;
  int voters_line = 1;
  int max_side = 480;
  double blur = -1, dmin = -1, dmax = -1;
};

// "out.png" -> "out_3.png" when several images are processed.
std::string numbered(const std::string& path, size_t index, size_t count) {
  if (count <= 1) return path;
  const auto dot = path.rfind('.');
  const std::string stem = dot == std::string::npos ? path : path.substr(0, dot);
  const std::string ext = dot == std::string::npos ? ".png" : path.substr(dot);
  return stem + "_" + std::to_string(index + 1) + ext;
}

// Defaults that scale with the photograph (the thesis' 25/250 px and blur 1 at 640x480).
void fill_image_defaults(const cv::Mat& image, const Options& opt, sym::Params* p, sym::EdgeParams* e) {
  const double short_side = std::min(image.cols, image.rows), long_side = std::max(image.cols, image.rows);
  *p = opt.params;
  *e = opt.edge;
  p->dmin = opt.dmin >= 0 ? opt.dmin : std::max(5.0, 0.05 * short_side);
  p->dmax = opt.dmax >= 0 ? opt.dmax : 0.5 * long_side;
  e->blur_sigma = opt.blur >= 0 ? opt.blur : std::max(1.0, short_side / 480.0);
  if (opt.canny.size() == 2) {
    e->canny_low = opt.canny[0];
    e->canny_high = opt.canny[1];
    e->auto_canny = false;
  } else {
    e->auto_canny = true;
  }
}

void write_image(const std::string& path, const cv::Mat& image) {
  if (!cv::imwrite(path, image)) throw std::runtime_error("cannot write " + path);
}

std::string json_for(const std::string& path, const sym::Result& r, const sym::Params& p,
                     const sym::EdgeParams& e) {
  JsonWriter j;
  j.begin_object();
  j.field("image", path).field("width", r.width).field("height", r.height).field("edges", r.num_edges);
  j.key("lines").begin_array();
  for (const auto& l : r.lines) {
    j.begin_object();
    j.field("r", l.r).field("theta_deg", l.theta * 180.0 / M_PI).field("votes", l.votes);
    j.field("x1", l.end1.x).field("y1", l.end1.y).field("x2", l.end2.x).field("y2", l.end2.y);
    j.field("seg_x1", l.seg1.x).field("seg_y1", l.seg1.y).field("seg_x2", l.seg2.x).field("seg_y2", l.seg2.y);
    if (l.skew != 0) j.field("skew_deg", l.skew * 180.0 / M_PI);
    j.end_object();
  }
  j.end_array();
  j.key("ms").begin_object();
  j.field("edges", r.ms.edges_ms).field("vote", r.ms.vote_ms).field("peaks", r.ms.peaks_ms);
  j.end_object();
  j.key("params").begin_object();
  j.field("dmin", p.dmin).field("dmax", p.dmax).field("theta_min", p.theta_min_deg).field("theta_max", p.theta_max_deg);
  j.field("blur", e.blur_sigma);
  if (!e.auto_canny) j.field("canny_low", e.canny_low).field("canny_high", e.canny_high);
  else j.field("canny", "auto");
  j.end_object();
  j.end_object();
  return j.str();
}

bool process(const std::string& path, size_t index, size_t count, const Options& opt) {
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) {
    log::error() << path << ": cannot read the image (missing, unreadable or not an image)";
    return false;
  }
  // Large photographs are detected at a working size (symmetry of whole objects is a coarse-scale
  // property, and the cost grows with the square of the edge count); lines are mapped back.
  cv::Mat work = image;
  const int long_side = std::max(image.cols, image.rows);
  if (opt.max_side > 0 && long_side > opt.max_side) {
    const double f = static_cast<double>(opt.max_side) / long_side;
    cv::resize(image, work, cv::Size(), f, f, cv::INTER_AREA);
  }
  sym::Params p;
  sym::EdgeParams e;
  fill_image_defaults(work, opt, &p, &e);
  sym::Detector detector(p, e);
  Stopwatch watch;
  cv::Mat edge_image;
  const sym::EdgeSet edges = sym::detect_edges(work, e, &edge_image);
  const double edges_ms = watch.elapsed_ms();
  sym::Result result = detector.detect(edges);
  result.ms.edges_ms = edges_ms;
  sym::Result reported = result;
  if (work.size() != image.size()) {
    reported.width = image.cols;
    reported.height = image.rows;
    for (auto& l : reported.lines) l = sym::map_line(l, work.size(), image.size());
  }
  std::cout << json_for(path, reported, p, e) << std::endl;

  // Pictures are drawn at the working size, where the edges live.
  if (!opt.draw.empty()) write_image(numbered(opt.draw, index, count), sym::draw_lines(edge_image, result.lines));
  if (!opt.edges_out.empty()) write_image(numbered(opt.edges_out, index, count), edge_image);
  if (!opt.accumulator.empty())
    write_image(numbered(opt.accumulator, index, count), sym::accumulator_image(detector.last_accumulator()));
  if (!opt.voters.empty() && opt.voters_line >= 1 && opt.voters_line <= static_cast<int>(result.lines.size())) {
    const sym::Line& line = result.lines[opt.voters_line - 1];
    write_image(numbered(opt.voters, index, count),
                sym::draw_voting_pairs(edge_image, detector.voting_pairs(edges, line), line));
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  log::set_component("detect");
  cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);  // we report bad files ourselves
  Options opt;
  Flags flags("nudge-detect",
              "Detects bilateral symmetry lines (Li 2008, Algorithm 1) and prints one JSON object per image.\n"
              "Lines are (r px, theta deg) about the image centre; theta = 0 is vertical.\n"
              "Images larger than --max-side are detected on a scaled copy and the lines mapped back.\n"
              "Defaults scale with the image: dmin 5% of the short side, dmax 50% of the long side,\n"
              "blur sigma max(1, short side / 480), Canny thresholds from the image's gradients.");
  flags.set_positional("IMAGE...", "image files");
  flags.add_int("lines", &opt.params.num_lines, "symmetry lines per image (Nlines)");
  flags.add_double("dmin", &opt.dmin, "minimum pairing distance, px (default: scaled)");
  flags.add_double("dmax", &opt.dmax, "maximum pairing distance, px; 0 = none (default: scaled)");
  flags.add_double("theta-min", &opt.params.theta_min_deg, "orientation limit, degrees");
  flags.add_double("theta-max", &opt.params.theta_max_deg, "orientation limit, degrees (min > max wraps)");
  flags.add_doubles("canny", &opt.canny, 2, "Canny thresholds LOW HIGH (default: from the image)");
  flags.add_double("blur", &opt.blur, "Gaussian blur sigma before Canny; 0 = none (default: scaled)");
  flags.add_double("min-peak-ratio", &opt.params.min_peak_ratio, "drop peaks below this fraction of the top");
  flags.add_int("suppress-r", &opt.params.suppress_r, "non-maximum suppression half-size in R, px");
  flags.add_int("suppress-theta", &opt.params.suppress_theta, "non-maximum suppression half-size, deg");
  flags.add_bool("once-per-row", &opt.params.once_per_row, "a row of Rot increments a bin at most once");
  flags.add_int("max-row-pixels", &opt.params.max_row_pixels, "skip rows of Rot with more pixels (0: off)");
  flags.add_bool("anti-alias", &opt.params.anti_alias, "3x3 Gaussian vote kernel");
  flags.add_string("skew", &opt.skew, "skew angles to try, degrees, comma-separated (e.g. -20,-10,10,20)");
  flags.add_int("threads", &opt.params.threads, "threads across angles");
  flags.add_int("max-side", &opt.max_side, "detect on a copy scaled to this long side, px (0: full size)");
  flags.add_string("draw", &opt.draw, "write the edges with the detected lines to this PNG");
  flags.add_string("edges", &opt.edges_out, "write the Canny edge image to this PNG");
  flags.add_string("accumulator", &opt.accumulator, "write the Hough accumulator (theta across, R down)");
  flags.add_string("voters", &opt.voters, "write the edge pairs that voted for line --voters-line");
  flags.add_int("voters-line", &opt.voters_line, "which line (1 = strongest) --voters shows");
  try {
    if (!flags.parse(argc, argv)) return 0;
    std::stringstream ss(opt.skew);
    for (std::string item; std::getline(ss, item, ',');)
      if (!item.empty()) opt.params.skew_deg.push_back(parse_double(item, "--skew"));
    sym::Params check = opt.params;
    check.dmin = std::max(0.0, opt.dmin);
    check.dmax = opt.dmax >= 0 ? opt.dmax : 0;
    sym::validate(check);
    if (opt.canny.size() == 2) sym::validate(sym::EdgeParams{0, opt.canny[0], opt.canny[1], false});
    if (opt.blur > 50) throw FlagError("--blur must be in [0, 50]");
  } catch (const std::exception& e) {
    std::cerr << "nudge-detect: " << e.what() << "\n";
    return 2;
  }
  if (flags.positional().empty()) {
    std::cerr << flags.help();
    return 2;
  }
  bool all_ok = true;
  const auto& images = flags.positional();
  for (size_t i = 0; i < images.size(); ++i) {
    try {
      all_ok &= process(images[i], i, images.size(), opt);
    } catch (const std::exception& e) {
      log::error() << images[i] << ": " << e.what();
      all_ok = false;
    }
  }
  return all_ok ? 0 : 1;
}
